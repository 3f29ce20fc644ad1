"""Which rows of PX4's own high-rate setpoint topics a lint reads (issue 31).

A ULog logs ``vehicle_rates_setpoint``, ``vehicle_thrust_setpoint`` and
``vehicle_torque_setpoint`` at 50 Hz (and the attitude and actuator setpoints at 10 Hz) in every
mode: PX4's own controllers publish them. The checks judge such a logged row only as the
external controller's (``checks._external.from_external``): while the recorded
``vehicle_status`` says OFFBOARD and the latest ``offboard_control_mode``'s first true field
selects that topic (``tables.control_mode``). Any other row is PX4's output, which no check or
the gate model reads; only the first row of each topic counts (OFB303 and the "not checkable"
notes ask whether the topic was logged at all).

So a lint reads, of these topics, the first row and the rows inside those windows, widened:
each window runs from the status (or declaration) that opens it to the next one plus
``MARGIN_S``, and a declaration window opens wherever any field that can select the topic is
true (the first true field may be another). Reading more rows than needed changes nothing;
``tests/test_ulog_thinning.py`` checks that the findings and the gate timelines of thinned and
whole reads are the same on every corpus ULog.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from fuzzoff import events as ev
from fuzzoff.events import NAV_STATE_OFFBOARD
from fuzzoff.tables.control_mode import ROVER_TABLE, TABLE_000, TABLE_002, TABLE_115, FlagRow

TABLES: tuple[dict[str, FlagRow], ...] = (TABLE_000, TABLE_002, TABLE_115, ROVER_TABLE)
"""Every table ``tables.control_mode.table_for`` hands out."""

THINNED_KINDS = (
    ev.RatesSetpoint.kind,
    ev.ThrustSetpoint.kind,
    ev.TorqueSetpoint.kind,
    ev.AttitudeSetpoint.kind,
    ev.ActuatorMotors.kind,
    ev.ActuatorServos.kind,
)
"""The setpoint kinds whose logged rows are thinned: PX4's controllers write them in every mode.
Not the trajectory setpoint (the plots and OFB404 read it), nor the rover setpoints."""

SELECTED_BY: dict[str, frozenset[str]] = {
    kind: frozenset(flag for table in TABLES for flag, row in table.items() if kind in row.allowed)
    for kind in THINNED_KINDS
}
"""Event kind -> the ``offboard_control_mode`` fields that, as the first true one, select it in
some release's table (rates: ``body_rate``; thrust and torque: ``thrust_and_torque`` or the
1.13-1.14 ``actuator``; ...)."""

MARGIN_S = 1.0
"""How long a window stays open past the status or declaration that closes it. The recorded
mode a check reads may lag the status by ``state.STALE_STATUS_S`` (0.05 s)."""

Columns = Mapping[str, Any]


class Windows:
    """Where a logged setpoint row may be the external controller's, from a ULog's status and
    declarations (``status``, ``declarations``: those topics' columns, None if not logged).
    Timestamps are pyulog's unsigned ones (``windows_for`` builds none otherwise)."""

    def __init__(self, status: Columns | None, declarations: Columns | None) -> None:
        self.offboard: tuple[Any, Any] | None = None
        """(starts, ends) in microseconds where the status says OFFBOARD; None: no status with a
        ``nav_state`` (the mode is then predicted: no row is ruled out by the mode)."""
        if status is not None and "nav_state" in status:
            self.offboard = _windows(status["timestamp"], status["nav_state"] == NAV_STATE_OFFBOARD)
        self.declarations = declarations
        if declarations is not None and "ignore_thrust" in declarations:
            self.declarations = None  # the legacy layout declares no first true field

    def rows(self, cols: Columns, kind: str) -> Any:
        """The rows of one topic instance of ``kind`` to read (sorted indices), or None: all."""
        fields = SELECTED_BY.get(kind)
        ts = cols["timestamp"]
        if fields is None or len(ts) == 0 or ts.dtype.kind != "u":
            return None
        keep = self._declared(ts, fields)
        if self.offboard is not None:
            keep &= _inside(ts, self.offboard)
        keep[int(np.argmin(ts))] = True  # the first row in time: the topic was logged
        if bool(keep.all()):
            return None
        return np.flatnonzero(keep)

    def _declared(self, ts: Any, fields: frozenset[str]) -> Any:
        """Rows where a declaration with any of ``fields`` true is the latest (widened)."""
        ocm = self.declarations
        present = [f for f in sorted(fields) if ocm is not None and f in ocm]
        if ocm is None or not present:
            # No boolean declaration with such a field logged: the declared flag never selects
            # this topic, so none of its logged rows is the external controller's.
            return np.zeros(len(ts), dtype=bool)
        selecting = np.zeros(len(ocm["timestamp"]), dtype=bool)
        for name in present:
            selecting |= ocm[name] != 0
        return _inside(ts, _windows(ocm["timestamp"], selecting))


def windows_for(datasets: list[Any]) -> Windows | None:
    """The windows of a ULog's loaded topic instances (pyulog ``Data``), or None (read every
    row) where they cannot be told simply: several instances of the status or declaration
    topic, or timestamps that are not unsigned (a damaged format)."""
    status = [d for d in datasets if d.name == "vehicle_status"]
    declarations = [d for d in datasets if d.name == "offboard_control_mode"]
    if len(status) > 1 or len(declarations) > 1:
        return None
    if any(d.data["timestamp"].dtype.kind != "u" for d in (*status, *declarations)):
        return None
    return Windows(
        status[0].data if status else None, declarations[0].data if declarations else None
    )


_MARGIN_US = np.uint64(MARGIN_S * 1e6)
_FOREVER = np.uint64(np.iinfo(np.uint64).max)


def _windows(ts: Any, on: Any) -> tuple[Any, Any]:
    """(starts, ends): each row where ``on`` holds opens a window that lasts until the next row
    in time plus ``MARGIN_S``; the last row's lasts for ever."""
    order = np.argsort(ts, kind="stable")
    sorted_ts = ts[order].astype(np.uint64, copy=False)
    held = np.asarray(on, dtype=bool)[order]
    ends = np.full(len(sorted_ts), _FOREVER, dtype=np.uint64)
    nxt = sorted_ts[1:]
    ends[:-1] = np.where(nxt < _FOREVER - _MARGIN_US, nxt + _MARGIN_US, _FOREVER)
    return sorted_ts[held], ends[held]


def _inside(ts: Any, windows: tuple[Any, Any]) -> Any:
    """Which of ``ts`` fall inside any window (closed intervals)."""
    starts, ends = windows
    if not len(starts):
        return np.zeros(len(ts), dtype=bool)
    reach = np.maximum.accumulate(ends)  # how far the windows opened so far reach
    t = ts.astype(np.uint64, copy=False)
    at = np.searchsorted(starts, t, side="right") - 1
    inside = at >= 0
    inside[inside] = t[inside] <= reach[at[inside]]
    return inside
