"""OFB801-OFB803: the uORB-era interface (seed 003): ``ignore_*`` flags and the setpoint triplet.

Seed 003 "Off-board control mode" and "position_setpoint_triplet 主题"; the controller
semantics of the ``ignore_*`` flags are in fuzzoff/tables/control_mode.py.
"""

from __future__ import annotations

from fuzzoff.checks._external import Episodes
from fuzzoff.checks._keepalive import mode_note
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import (
    Event,
    LegacyControlMode,
    PositionSetpointTriplet,
    SetPositionTargetLocal,
    VehicleStatus,
)
from fuzzoff.gate import GateTransition
from fuzzoff.tables.control_mode import (
    legacy_controllers,
    legacy_disabled_by_acceleration,
    legacy_mode_from_mask,
)


class LegacyAccelerationNotIgnored(Check):
    """OFB801: acceleration/force not ignored switches position and velocity control off."""

    codes = ("OFB801",)
    wants = (LegacyControlMode, SetPositionTargetLocal)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB801")

    def on_event(self, event: Event) -> None:
        if isinstance(event, SetPositionTargetLocal):
            # The legacy receiver turns the type_mask into offboard_control_mode (gate 6.5).
            mode = legacy_mode_from_mask(event)
            key = "mask"
            what = (
                f"SET_POSITION_TARGET_LOCAL_NED type_mask {event.type_mask} leaves the "
                "acceleration bits clear"
            )
        else:
            assert isinstance(event, LegacyControlMode)
            mode = event
            key = "mode"
            what = "offboard_control_mode.ignore_acceleration_force is false"
        disabled = " and ".join(legacy_disabled_by_acceleration(mode))
        if not disabled:
            self.episodes.good(key)
            return
        self.episodes.bad(
            key,
            event.t,
            event.where,
            f"{what} with {disabled} not ignored: enabling acceleration/force disables "
            f"{disabled} control",
            short=f"acceleration used with {disabled}: it switches {disabled} control off",
        )

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()


class LegacyTripletCurrentOnly(Check):
    """OFB802: ``previous``/``next`` of the triplet are filled in offboard but never used."""

    codes = ("OFB802",)
    wants = (PositionSetpointTriplet, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB802")

    def on_event(self, event: Event) -> None:
        if not self.ctx.in_offboard:
            self.episodes.close_all()
            return
        if not isinstance(event, PositionSetpointTriplet):
            return
        filled = [n for n in ("previous", "next") if getattr(event, f"{n}_valid")]
        if not filled:
            self.episodes.good("triplet")
            return
        self.episodes.bad(
            "triplet",
            event.t,
            event.where,
            f"position_setpoint_triplet {' and '.join(filled)} filled in offboard: only "
            f"current is used{mode_note(self.ctx)}",
        )

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()


class LegacySetpointInvalid(Check):
    """OFB803: in offboard, ``current`` invalid, or invalid for the enabled control."""

    codes = ("OFB803",)
    wants = (PositionSetpointTriplet, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB803")

    def on_event(self, event: Event) -> None:
        if not self.ctx.in_offboard:
            self.episodes.close_all()
            return
        if not isinstance(event, PositionSetpointTriplet):
            return
        problem = self._problem(event)
        if problem is None:
            self.episodes.close_all()
            return
        self.episodes.bad(
            problem,
            event.t,
            event.where,
            f"position_setpoint_triplet in offboard with {problem}: no control happens on "
            f"that axis{mode_note(self.ctx)}",
        )

    def _problem(self, sp: PositionSetpointTriplet) -> str | None:
        if not sp.current_valid:
            return "current.valid false"
        mode = self.ctx.state.control_mode
        if not isinstance(mode, LegacyControlMode):
            return None
        enabled = legacy_controllers(mode)
        if enabled.position and not sp.current_position_valid:
            return "position control enabled but current.position_valid false"
        if not enabled.position and enabled.velocity and not sp.current_velocity_valid:
            return "velocity control enabled but current.velocity_valid false"
        return None

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()
