"""First cut of the gate model: proof of life, request acceptance and the loss failsafe.

Interface (kept stable for the engine and the checks):

* ``GateModel(profile, params=None, vehicle="")``
* ``feed(event) -> list[GateTransition]``: advance to ``event.t``, then apply the event;
* ``finish(t_end) -> list[GateTransition]``;
* ``signal_ok``, ``armed``, ``user_intention``, ``nav_state``, ``in_offboard``, ``params``.
"""

from __future__ import annotations

from collections.abc import Mapping

from fuzzoff.events import (
    NAV_STATE_OFFBOARD,
    Command,
    CommandAck,
    ControlMode,
    Event,
    LegacyControlMode,
    MavlinkTarget,
    Parameter,
    VehicleStatus,
)
from fuzzoff.gate.transitions import GateTransition
from fuzzoff.profiles import Profile

LOSS_ACTIONS = {
    0: (2, "POSCTL"),
    1: (1, "ALTCTL"),
    2: (15, "STAB"),
    3: (5, "AUTO_RTL"),
    4: (18, "AUTO_LAND"),
    5: (4, "AUTO_LOITER"),
    6: (13, "TERMINATION"),
    7: (None, "DISARM"),
}


def default_params(profile: Profile) -> dict[str, float]:
    """PX4's defaults for the parameters the gate reads (gate spec section 13)."""
    return {
        "COM_OF_LOSS_T": 0.0 if profile.px4 == "legacy" else 0.5 if profile.px4 == "1.11" else 1.0,
        "COM_OBL_RC_ACT": 0.0,
        "COM_OBL_ACT": 0.0,
        "MAV_FWDEXTSP": 1.0,
    }


class GateModel:
    def __init__(
        self, profile: Profile, params: Mapping[str, float] | None = None, vehicle: str = ""
    ) -> None:
        self.profile = profile
        self.vehicle = vehicle
        self.overrides = dict(params or {})
        self.params = default_params(profile) | self.overrides
        self.last_keepalive: float | None = None
        self.signal_ok = False
        self.armed = False
        self.user_intention: int | None = None
        self.nav_state: int | None = None
        self._now = 0.0

    @property
    def in_offboard(self) -> bool:
        return self.nav_state == NAV_STATE_OFFBOARD

    @property
    def loss_timeout(self) -> float:
        if self.profile.px4 == "legacy":
            return 0.5
        return float(self.params["COM_OF_LOSS_T"])

    def _tr(self, t: float, **kw: object) -> GateTransition:
        return GateTransition(t=t, vehicle=self.vehicle, **kw)  # type: ignore[arg-type]

    def _advance(self, t: float) -> list[GateTransition]:
        out: list[GateTransition] = []
        if self.signal_ok and self.last_keepalive is not None:
            lost_at = self.last_keepalive + self.loss_timeout
            if t >= lost_at:
                self.signal_ok = False
                out.append(
                    self._tr(
                        lost_at,
                        what="signal_lost",
                        spec="2.1",
                        message=f"no keep-alive for {self.loss_timeout:.2f} s",
                    )
                )
                if self.armed and self.user_intention == NAV_STATE_OFFBOARD:
                    nav, action = LOSS_ACTIONS.get(
                        int(self.params["COM_OBL_RC_ACT"]), LOSS_ACTIONS[0]
                    )
                    self.nav_state = nav
                    out.append(
                        self._tr(
                            lost_at,
                            what="failsafe",
                            spec="5.1",
                            action=action,
                            nav_state=nav,
                            message=f"offboard lost: {action}",
                        )
                    )
        self._now = max(self._now, t)
        return out

    def feed(self, event: Event) -> list[GateTransition]:
        out = self._advance(event.t)
        if isinstance(event, (ControlMode, LegacyControlMode, MavlinkTarget)):
            if isinstance(event, ControlMode) and not event.flags():
                return out
            self.last_keepalive = event.t
            if not self.signal_ok:
                self.signal_ok = True
                out.append(
                    self._tr(
                        event.t,
                        what="signal_available",
                        spec="2.1",
                        cause=event,
                        message="offboard signal available",
                    )
                )
                if (
                    self.armed
                    and self.user_intention == NAV_STATE_OFFBOARD
                    and not self.in_offboard
                ):
                    self.nav_state = NAV_STATE_OFFBOARD
                    out.append(
                        self._tr(
                            event.t,
                            what="offboard_resumed",
                            spec="5.1",
                            cause=event,
                            nav_state=NAV_STATE_OFFBOARD,
                            message="back in OFFBOARD",
                        )
                    )
        elif isinstance(event, Parameter) and event.name in self.params:
            if event.name not in self.overrides:
                self.params[event.name] = event.value
        elif isinstance(event, VehicleStatus):
            if self.user_intention is None and event.nav_state is not None:
                self.user_intention = event.user_intention or event.nav_state
                self.nav_state = event.nav_state
            if event.armed is not None and not self.armed:
                self.armed = event.armed
        elif isinstance(event, Command):
            out.extend(self._command(event))
        elif isinstance(event, CommandAck):
            pass
        return out

    def _command(self, cmd: Command) -> list[GateTransition]:
        if cmd.is_offboard_switch:
            ok = self.signal_ok or (not self.armed and self.profile.at_least("1.14"))
            if ok:
                self.user_intention = NAV_STATE_OFFBOARD
                self.nav_state = NAV_STATE_OFFBOARD
                return [
                    self._tr(
                        cmd.t,
                        what="request_accepted",
                        spec="4.1",
                        cause=cmd,
                        nav_state=NAV_STATE_OFFBOARD,
                        message="switch to OFFBOARD accepted",
                    )
                ]
            return [
                self._tr(
                    cmd.t,
                    what="request_rejected",
                    spec="4.1",
                    cause=cmd,
                    reason="no offboard signal",
                    message="switch to OFFBOARD rejected: no offboard signal",
                )
            ]
        if cmd.is_arm:
            if (
                self.user_intention == NAV_STATE_OFFBOARD
                and self.profile.at_least("1.14")
                and not self.signal_ok
            ):
                return [
                    self._tr(
                        cmd.t,
                        what="arm_rejected",
                        spec="4.2",
                        cause=cmd,
                        reason="no offboard signal",
                        message="arming in OFFBOARD rejected: no offboard signal",
                    )
                ]
            self.armed = True
            return [self._tr(cmd.t, what="arm_accepted", spec="4.2", cause=cmd, message="armed")]
        if cmd.is_disarm:
            self.armed = False
            return [self._tr(cmd.t, what="disarmed", spec="4.2", cause=cmd, message="disarmed")]
        if cmd.is_mode_switch:
            self.user_intention = None
            self.nav_state = None
        return []

    def finish(self, t_end: float) -> list[GateTransition]:
        return self._advance(t_end)
