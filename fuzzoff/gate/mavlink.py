"""MAVLink setpoints as PX4's receiver takes them (gate.md#receiver): one part of ``GateModel``.

``MavlinkSetpoints`` runs each SET_POSITION_TARGET_* / SET_ATTITUDE_TARGET through the receiver
model (``receiver.receive``): a dropped message is a ``setpoint_dropped`` transition (once per run
with the same reason), a taken one is a keep-alive with the flags the receiver sets
(``keepalive.KeepAlives``) and a setpoint for the controllers (``setpoints.Controllers``).
"""

from __future__ import annotations

from fuzzoff.events import NAV_STATE_OFFBOARD, SetPositionTargetLocal
from fuzzoff.gate.keepalive import KeepAlives
from fuzzoff.gate.landed import climbs
from fuzzoff.gate.receiver import DROPPED, SHAPES, Result, Shape, receive
from fuzzoff.gate.setpoints import Controllers
from fuzzoff.gate.state import GateState


class MavlinkSetpoints:
    def __init__(self, state: GateState, keepalives: KeepAlives, controllers: Controllers) -> None:
        self.s = state
        self.keepalives = keepalives
        self.controllers = controllers
        self.verdicts: dict[Shape, Result] = {}
        """``receive``'s accepted verdicts by message shape (``receiver.shape``) under the current
        receiver context: cleared (``forget``) when a parameter or an estimate changes."""
        self.drop_reason: str | None = None
        """The reason of the run of dropped (or partly ignored) messages under way."""

    def forget(self) -> None:
        """The receiver context changed: the remembered verdicts no longer hold."""
        self.verdicts.clear()

    def _receive(self, event: SetPositionTargetLocal, key: Shape | None) -> Result:
        """``receive(event, rx)``, remembered under ``key`` (its shape). Only verdicts without
        a reason are kept: a reason's text shows field values, whose repr the shape does not
        fix (``1`` and ``True`` are the same key)."""
        verdict = receive(event, self.s.rx)
        if key is not None and verdict[2] is None:
            self.verdicts[key] = verdict
        return verdict

    def setpoint(self, event: SetPositionTargetLocal) -> bool:
        key = SHAPES[type(event)](event)
        verdict = self.verdicts.get(key) if key is not None else None
        if verdict is None:
            verdict = self._receive(event, key)
        mask, axes, reason, spec = verdict
        if mask == DROPPED:
            if reason != self.drop_reason:
                self.drop_reason = reason
                self.s.emit(
                    event.t,
                    "setpoint_dropped",
                    f"{event.kind.upper()} dropped, no keep-alive: {reason}",
                    spec,
                    reason=reason,
                )
            return True
        if reason is not None and reason != self.drop_reason:
            self.drop_reason = reason
            self.s.emit(
                event.t,
                "setpoint_dropped",
                f"{event.kind.upper()}: {reason}",
                spec,
                reason=reason,
                unverified="unverified" in reason,
            )
        elif reason is None:
            self.drop_reason = None
        # Taken: a keep-alive, and a setpoint in OFFBOARD (one method: once per message).
        s = self.s
        t = event.t
        dirty = self.keepalives.keepalive(t, mask, event)
        if s.landed.watching and s.nav == NAV_STATE_OFFBOARD:
            s.landed.setpoint(t, isinstance(event, SetPositionTargetLocal) and climbs(event))
        if not axes:
            return dirty
        if s.nav == NAV_STATE_OFFBOARD:
            if s.ctl.trajectory(t, axes, True):
                dirty = True
                self.controllers.update(t)
        elif s.ctl.legacy:
            s.ctl.setpoint(t)  # legacy: counted once offboard runs (section 8)
        return dirty
