"""What the ROS 2 / uORB content rules share: whose setpoint it is, the mode note, episodes.

A ULog logs PX4's own setpoints next to the external controller's, so a logged (origin
``vehicle``) setpoint counts as external only in offboard as the recorded status says it (not
at an accepted ack: PX4 1.16 and 1.17 ack a switch from the MAVLink receiver before Commander
makes it, and PX4's flight task still writes ``trajectory_setpoint`` until the status changes),
not while a VTOL is in transition (PX4's transition flight task writes it then, in OFFBOARD too)
and only when the declared first true field selects its topic
(fuzzoff/tables/control_mode.py). Messages recorded on their way to the vehicle (origin
``sent``: ROS 2 ``/fmu/in``, MAVLink) are always external.
"""

from __future__ import annotations

from operator import attrgetter

from fuzzoff.checks._runs import first_of_each
from fuzzoff.checks.base import CheckContext
from fuzzoff.events import NAV_STATE_OFFBOARD, Event, Where
from fuzzoff.findings import Severity
from fuzzoff.lean_dataclass import dataclass


def declared_flag(ctx: CheckContext) -> str | None:
    """The first true field of the latest ``OffboardControlMode`` (None: none seen, or empty)."""
    return ctx.state.declared_flag


def from_external(ctx: CheckContext, event: Event) -> bool:
    """Was this setpoint written by the external controller (see the module docstring)?"""
    if event.origin == "sent":
        return True
    state = ctx.state
    if event.origin != "vehicle" or not ctx.in_offboard:
        return False
    if state.mode_recorded and state.status_nav_state != NAV_STATE_OFFBOARD:
        return False  # accepted, but PX4 has not switched yet: its own flight task writes
    if state.vtol_phase == "transition":
        return False  # a VTOL between MC and FW: PX4's transition flight task writes
    row = ctx.row_for(state.declared_flag)
    return row is not None and event.kind in row.allowed


_ORIGIN_KIND = attrgetter("origin", "kind")


def external_only(ctx: CheckContext, events: list[Event]) -> list[Event]:
    """The external controller's messages among ``events`` of one run, in order: ``events``
    itself when all are. Within a run the state is fixed, so ``from_external`` depends only on
    a message's origin and kind and is asked once per pair."""
    if not events:
        return events
    first = first_of_each(_ORIGIN_KIND, events)
    keep = {pair for pair, event in first.items() if from_external(ctx, event)}
    if len(keep) == len(first):
        return events
    if not keep:
        return []
    return [event for event in events if _ORIGIN_KIND(event) in keep]


def is_armed(ctx: CheckContext) -> bool:
    """Armed as recorded, else as the gate model predicts from the recorded commands."""
    if ctx.state.armed is not None:
        return ctx.state.armed
    return bool(ctx.gate.armed)


@dataclass(slots=True)
class Episode:
    """A run of consecutive bad messages, reported once when it ends (or at ``finish``)."""

    start: float
    where: Where
    message: str
    last: float
    count: int = 1
    severity: Severity | None = None
    short: str = ""


class Episodes:
    """Open/extend/close runs of one condition per key, reporting each run as one finding."""

    def __init__(self, ctx: CheckContext, code: str) -> None:
        self.ctx = ctx
        self.code = code
        self.open: dict[str, Episode] = {}

    def bad(
        self,
        key: str,
        t: float,
        where: Where,
        message: str,
        severity: Severity | None = None,
        short: str = "",
    ) -> None:
        episode = self.open.get(key)
        if episode is None:
            self.open[key] = Episode(t, where, message, t, severity=severity, short=short)
        else:
            episode.last = t
            episode.count += 1

    def extend(self, key: str, last: float, count: int) -> None:
        """``bad(key, ...)`` for ``count`` more messages, the newest at ``last``, with ``key``
        already open (a run of messages that all commit it): only its end and count move."""
        episode = self.open[key]
        episode.last = last
        episode.count += count

    def good(self, key: str) -> None:
        if not self.open:  # the usual clean message with nothing open
            return
        episode = self.open.pop(key, None)
        if episode is not None:
            self._report(episode)

    def close_all(self) -> None:
        if self.open:  # usually nothing is open: skip the copy of the keys
            for key in list(self.open):
                self.good(key)

    def _report(self, episode: Episode) -> None:
        message = episode.message
        if episode.count > 1:
            message += f" ({episode.count} messages until {episode.last:.3f} s)"
        self.ctx.report(
            self.code,
            message,
            episode.start,
            episode.where,
            severity=episode.severity,
            end=episode.last if episode.count > 1 else None,
            short=episode.short,
        )
