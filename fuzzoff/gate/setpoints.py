"""Which controller runs on the offboard setpoints (gate.md#control-mode to #rover): one part of
``GateModel``.

``Controllers`` hands the setpoints PX4's controllers read (``TrajectorySetpoint``, legacy's
``position_setpoint_triplet``, and what ``mavlink.MavlinkSetpoints`` passes on) to the
``tracker.ControllerTracker`` and turns each change of what runs into a ``controller``
transition. The tables are in ``controllers``.
"""

from __future__ import annotations

from fuzzoff.events import NAV_STATE_OFFBOARD, PositionSetpointTriplet, TrajectorySetpoint
from fuzzoff.gate import controllers
from fuzzoff.gate.landed import climbs
from fuzzoff.gate.signal import INF
from fuzzoff.gate.state import GateState


class Controllers:
    def __init__(self, state: GateState) -> None:
        self.s = state

    def update(self, t: float) -> None:
        """What runs at ``t`` in the effective mode: a transition if that changed."""
        s = self.s
        s.ctl.land_speed = float(s.params.get("MPC_LAND_SPEED", 0.7))
        change = s.ctl.update(t, s.nav)
        if change is not None:
            s.emit(
                t,
                "controller",
                change.text,
                change.spec,
                reason=change.reason,
                unverified=change.unverified,
                cause=None,
            )

    def reuse_due(self) -> float:
        """1.16+: when a reused last valid setpoint expires (inf if none)."""
        return self.s.ctl.reuse_due

    def reuse_expired(self, t: float) -> None:
        self.s.ctl.reuse_due = INF
        self.update(t)

    def trajectory(self, event: TrajectorySetpoint) -> bool:
        s = self.s
        t = event.t
        offboard = s.nav == NAV_STATE_OFFBOARD
        if s.landed.watching and offboard:
            s.landed.setpoint(t, climbs(event))
        changed = s.ctl.trajectory(t, controllers.axes_of(event), offboard)
        if changed:
            self.update(t)
        return changed

    def triplet(self, event: PositionSetpointTriplet) -> bool:
        """legacy/1.11: the offboard setpoint as mc_pos_control sees it (section 8)."""
        ctl = self.s.ctl
        if ctl.legacy and event.current_valid and ctl.setpoint(event.t):
            self.update(event.t)
        return False
