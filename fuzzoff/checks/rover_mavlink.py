"""OFB507-OFB509: MAVLink setpoints sent to a rover (seed 000 "Ровер", MAVLink part; seed 002
"无人车").

OFB507: SET_ATTITUDE_TARGET is not supported for rovers (1.15+ page), and only its yaw is used
(1.13-1.14 page). OFB508: fields rover modules ignore (acceleration, ``z``, and yaw / yaw rate
on Ackermann and differential rovers). OFB509: rover MAVLink setpoints while ``MAV_FWDEXTSP``
is 0 (the parameter as recorded, or as given in ``params``; without it, OFB002).
"""

from __future__ import annotations

import math

from fuzzoff import type_mask as tmask
from fuzzoff.checks._episodes import Episodes, Offence
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.checks.mavlink_fields import set_components
from fuzzoff.events import (
    Event,
    MavlinkTarget,
    Parameter,
    Quat,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    Where,
)
from fuzzoff.findings import Severity
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.tables import mavlink as tm

TILT_TOLERANCE_RAD = math.radians(1.0)
"""Roll or pitch beyond this in a rover's attitude target is a request the rover cannot follow."""

FWDEXTSP = "MAV_FWDEXTSP"


def roll_pitch(q: Quat) -> tuple[float, float]:
    """Roll and pitch (rad) of a (w, x, y, z) quaternion."""
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    sin_pitch = max(-1.0, min(1.0, 2 * (w * y - z * x)))
    return roll, math.asin(sin_pitch)


class RoverAttitudeTarget(Check):
    codes = ("OFB507",)
    wants = (SetAttitudeTarget,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)

    def on_event(self, event: Event) -> None:
        if event.origin != "sent" or not isinstance(event, SetAttitudeTarget):
            return
        rules = tm.attitude_rules(self.ctx.profile)
        if rules is None or not self.ctx.profile.is_rover:
            return
        px4 = self.ctx.profile.px4
        offences: dict[str, Offence] = {}
        if not rules.supported:
            offences["unsupported"] = Offence(
                f"SET_ATTITUDE_TARGET to a rover: the PX4 {px4} docs do not support it for "
                "rover offboard control; the rover modes do not use it (use "
                "SET_POSITION_TARGET_* or the ROS 2 rover setpoints)"
            )
        elif not tm.attitude_used(event.type_mask):
            offences["rates"] = Offence(
                f"SET_ATTITUDE_TARGET type_mask {event.type_mask} to a rover without an "
                f"attitude: the PX4 {px4} docs support only an attitude (of which only the yaw "
                "is used) for rovers"
            )
        elif rules.yaw_only:
            # works on this release only (rules.md: warning): the 1.15+ docs do not support it
            roll, pitch = roll_pitch(event.q)
            tilt = ""
            if max(abs(roll), abs(pitch)) > TILT_TOLERANCE_RAD:
                tilt = (
                    f" (the roll {math.degrees(roll):.1f} deg and pitch "
                    f"{math.degrees(pitch):.1f} deg it asks for are ignored)"
                )
            offences["yaw_only"] = Offence(
                f"SET_ATTITUDE_TARGET to a rover: PX4 {px4} uses only its yaw{tilt}; from 1.15 "
                "the docs do not support it for rovers (use SET_POSITION_TARGET_*)",
                Severity.WARNING,
            )
        self.episodes.update("OFB507", event.kind, event.t, event.where, offences)

    def finish(self, t_end: float) -> None:
        self.episodes.finish()


class RoverIgnoredFields(Check):
    codes = ("OFB508",)
    wants = (SetPositionTargetLocal, SetPositionTargetGlobal)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.yaw_ignored = ctx.profile.vehicle in tm.ROVER_YAW_IGNORED

    def on_event(self, event: Event) -> None:
        if event.origin != "sent" or not isinstance(
            event, (SetPositionTargetLocal, SetPositionTargetGlobal)
        ):
            return
        rules = tm.position_rules(self.ctx.profile, event.kind)
        if rules is None or not self.ctx.profile.is_rover:
            return
        name = tm.MESSAGE_NAMES[event.kind]
        mask = event.type_mask
        offences: dict[str, Offence] = {}
        if "acceleration" in rules.ignored:
            accel = set_components(event, "acceleration")
            if accel:
                offences["acceleration"] = Offence(
                    f"rover {name} sets {', '.join(accel)}: rover modules ignore acceleration "
                    "setpoints"
                )
        vertical = [c for c in set_components(event, "velocity") if c == "vz"]
        if isinstance(event, SetPositionTargetLocal):
            z = event.position[2]
            if not mask & tmask.Z_IGNORE and z != 0 and not math.isnan(z):
                vertical.insert(0, "z")
        if vertical:
            offences["z"] = Offence(
                f"rover {name} sets {', '.join(vertical)}: rover modules use only the "
                "horizontal components"
            )
        if self.yaw_ignored:
            yaw = [
                n
                for n, bit in (("yaw", tmask.YAW_IGNORE), ("yaw_rate", tmask.YAW_RATE_IGNORE))
                if not mask & bit
            ]
            if yaw:
                offences["yaw"] = Offence(
                    f"rover {name} uses {' and '.join(yaw)} (type_mask {mask}): "
                    f"{self.ctx.profile.vehicle} rovers ignore it (in velocity control the "
                    "yaw follows the velocity direction); only mecanum rovers use it"
                )
        self.episodes.update("OFB508", event.kind, event.t, event.where, offences)

    def finish(self, t_end: float) -> None:
        self.episodes.finish()


@dataclass(slots=True)
class _Unjudged:
    kind: str
    t: float
    where: Where
    last_t: float
    count: int = 1


class RoverNotForwarded(Check):
    codes = ("OFB509",)
    wants = (MavlinkTarget, Parameter)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        given = ctx.settings.params.get(FWDEXTSP)
        self.value: float | None = None if given is None else float(given)
        self.user_value = given is not None
        self.unjudged: _Unjudged | None = None
        """Setpoints seen before the parameter was: judged once it shows up."""

    def on_event(self, event: Event) -> None:
        if isinstance(event, Parameter):
            if event.name == FWDEXTSP and not self.user_value:
                self.value = event.value
                self._judge_earlier()
            return
        if event.origin != "sent" or not isinstance(event, MavlinkTarget):
            return
        if self.value is None:
            if self.unjudged is None:
                self.unjudged = _Unjudged(event.kind, event.t, event.where, event.t)
            else:
                self.unjudged.last_t = event.t
                self.unjudged.count += 1
            return
        offences = {} if self.value else {"off": Offence(self._message(event.kind))}
        self.episodes.update("OFB509", "setpoints", event.t, event.where, offences)

    def _message(self, kind: str) -> str:
        return (
            f"rover MAVLink setpoint ({tm.MESSAGE_NAMES.get(kind, kind)}) while "
            f"{FWDEXTSP} = 0: PX4 does not forward external setpoints, so the rover gets no "
            "setpoint (and, in PX4's code, no keep-alive)"
        )

    def _judge_earlier(self) -> None:
        seen, self.unjudged = self.unjudged, None
        if seen is None or self.value:
            return
        span = (seen.t, seen.where, seen.last_t, seen.count)
        self.episodes.start("OFB509", "setpoints", "off", Offence(self._message(seen.kind)), span)

    def finish(self, t_end: float) -> None:
        self.episodes.finish()
        if self.unjudged is not None:
            self.ctx.cannot_check(
                "OFB509",
                f"needs the {FWDEXTSP} parameter (PARAM_VALUE or ULog parameters)",
            )
