"""OFB501-OFB506: ROS 2 offboard control of a rover (seed 000 "Ровер", PX4 1.16+).

The rover setpoints form a hierarchy: the highest one published drives the ones below it, so
only the docs' combinations are valid (position alone, or speed/throttle with attitude, rate or
steering), each with one ``OffboardControlMode`` flag and some setpoints published as NaN. The
tables are in ``fuzzoff.tables.rover``. What counts as "published" is the last message of each
rover setpoint topic within ``window_s`` before an ``OffboardControlMode`` in offboard.
"""

from __future__ import annotations

from fuzzoff.checks._episodes import Episodes, Offence
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import (
    ActuatorMotors,
    ActuatorServos,
    ControlMode,
    Event,
    RoverAttitudeSetpoint,
    RoverPositionSetpoint,
    RoverRateSetpoint,
    RoverSpeedSetpoint,
    RoverSteeringSetpoint,
    RoverThrottleSetpoint,
    TrajectorySetpoint,
)
from fuzzoff.findings import Severity
from fuzzoff.tables import rover as tr

ROVER_SETPOINTS = (
    RoverPositionSetpoint,
    RoverSpeedSetpoint,
    RoverAttitudeSetpoint,
    RoverRateSetpoint,
    RoverThrottleSetpoint,
    RoverSteeringSetpoint,
)


ULOG_NOTE = (
    "needs the ROS 2 topics as sent (/fmu/in/...): a ULog logs PX4's own copies, which the "
    "rover modules also write"
)


def flags_text(mode: ControlMode) -> str:
    return ", ".join(mode.flags()) or "none"


def logged_only(ctx: CheckContext, codes: tuple[str, ...], kinds: tuple[str, ...]) -> bool:
    """A ULog cannot tell the companion's setpoints from PX4's own: say so (OFB002)."""
    if ctx.info.format != "ulog":
        return False
    if ctx.has(*kinds):
        for code in codes:
            ctx.cannot_check(code, ULOG_NOTE)
    return True


class RoverTrajectory(Check):
    """OFB501 (deprecated TrajectorySetpoint) and OFB505 (Ackermann yaw)."""

    codes = ("OFB501", "OFB505")
    wants = (TrajectorySetpoint,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.tables = tr.rover_tables(ctx.profile)
        logged_only(ctx, self.codes, (TrajectorySetpoint.kind,))

    def on_event(self, event: Event) -> None:
        if event.origin != "sent" or self.tables is None or not self.ctx.profile.is_rover:
            return
        px4 = self.ctx.profile.px4
        self.episodes.update(
            "OFB501",
            "trajectory",
            event.t,
            event.where,
            {
                "deprecated": Offence(
                    f"rover driven with TrajectorySetpoint: deprecated for rovers on PX4 {px4}; "
                    "publish the rover setpoints (RoverPositionSetpoint, RoverSpeedSetpoint, ...)"
                )
            },
        )
        mode = self.ctx.state.control_mode
        yaw_flag = isinstance(mode, ControlMode) and mode.first_flag() == "attitude"
        unsupported = self.ctx.profile.vehicle in self.tables.yaw_unsupported
        offences = {}
        if yaw_flag and unsupported:
            offences["yaw"] = Offence(
                "TrajectorySetpoint with the OffboardControlMode attitude flag (a yaw "
                "setpoint) to an Ackermann rover: Ackermann rovers do not support the yaw "
                "setpoint, so nothing drives the rover"
            )
        self.episodes.update("OFB505", "trajectory", event.t, event.where, offences)

    def finish(self, t_end: float) -> None:
        self.episodes.finish()


class RoverCombination(Check):
    """OFB502-OFB504: the published rover setpoints against the docs' combination table."""

    codes = ("OFB502", "OFB503", "OFB504")
    wants = (*ROVER_SETPOINTS, ControlMode)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.tables = tr.rover_tables(ctx.profile)
        self.window = float(ctx.option("OFB502", "window_s"))
        self.nan_window = float(ctx.option("OFB504", "window_s"))
        self.last: dict[str, tuple[float, bool]] = {}
        """Rover setpoint kind -> (time of its last message, whether it carried a value)."""
        logged_only(ctx, self.codes, tr.ROVER_KINDS)

    def on_event(self, event: Event) -> None:
        if self.tables is None or not self.ctx.profile.is_rover:
            return
        if isinstance(event, ROVER_SETPOINTS):
            if event.origin == "sent":
                self.last[event.kind] = (event.t, tr.has_value(event))
            return
        if not isinstance(event, ControlMode):
            return
        # direct_actuator too: rover setpoints published under it are ignored by PX4, so they
        # do not match the flag their combination needs (OFB503)
        if not self.ctx.in_offboard or event.first_flag() is None:
            self._clear()
            return
        published = {k for k, (t, _) in self.last.items() if event.t - t <= self.window}
        with_value = frozenset(k for k in published if self.last[k][1])
        if not with_value:
            self._clear()  # nothing published yet, or the deprecated TrajectorySetpoint path
            return
        row = tr.match(self.tables.combinations, with_value)
        self.episodes.update(
            "OFB502", "rover", event.t, event.where, self._invalid(row, with_value)
        )
        self.episodes.update("OFB503", "rover", event.t, event.where, self._flags(row, event))
        self.episodes.update(
            "OFB504", "rover", event.t, event.where, self._nan(row, with_value, event.t)
        )

    def _invalid(
        self, row: tr.RoverCombination | None, with_value: frozenset[str]
    ) -> dict[str, Offence]:
        if row is not None:
            return {}
        valid = "; ".join(r.name for r in self.tables.combinations) if self.tables else ""
        return {
            f"invalid:{sorted(with_value)}": Offence(
                f"rover setpoints published with values: {tr.names(with_value)}; not one of the "
                f"valid combinations ({valid})",
                short=f"{tr.names(with_value)}: not a valid rover setpoint combination",
            )
        }

    def _flags(self, row: tr.RoverCombination | None, mode: ControlMode) -> dict[str, Offence]:
        if row is None or mode.flags() == (row.flag,):
            return {}
        return {
            f"flags:{row.name}:{mode.flags()}": Offence(
                f"rover setpoints form {row.name}, which needs OffboardControlMode "
                f"{row.flag} alone; the flags set are: {flags_text(mode)}",
                short=f"{row.name} needs '{row.flag}' alone; set: {flags_text(mode)}",
            )
        }

    def _nan(
        self, row: tr.RoverCombination | None, with_value: frozenset[str], now: float
    ) -> dict[str, Offence]:
        if row is None or not row.nan:
            return {}
        carry = row.nan & with_value
        missing = {
            k
            for k in row.nan - with_value
            if k not in self.last or now - self.last[k][0] > self.nan_window
        }
        if not carry and not missing:
            return {}
        parts = []
        if carry:
            parts.append(f"{tr.names(carry)} carries a value")
        if missing:
            parts.append(f"{tr.names(missing)} is not published")
        return {
            f"nan:{row.name}:{sorted(carry)}:{sorted(missing)}": Offence(
                f"{row.name} needs {tr.names(row.nan)} published as NaN, but "
                f"{' and '.join(parts)}: the rover module's hierarchy overrides the intended "
                "setpoint",
                short=f"{row.name}: {' and '.join(parts)} (needs NaN)",
            )
        }

    def _clear(self) -> None:
        for code in self.codes:
            self.episodes.clear(code)

    def finish(self, t_end: float) -> None:
        self.episodes.finish()


class RoverDirectActuator(Check):
    """OFB506: actuator setpoints need ``direct_actuator`` as the only true flag."""

    codes = ("OFB506",)
    wants = (ActuatorMotors, ActuatorServos)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        logged_only(ctx, self.codes, (ActuatorMotors.kind, ActuatorServos.kind))

    def on_event(self, event: Event) -> None:
        if event.origin != "sent" or not self.ctx.profile.is_rover:
            return
        tables = tr.rover_tables(self.ctx.profile)
        mode = self.ctx.state.control_mode
        if tables is None or not isinstance(mode, ControlMode) or not self.ctx.in_offboard:
            self.episodes.clear("OFB506")
            return
        offences = {}
        if mode.flags() != (tables.direct_actuator_flag,):
            offences[",".join(mode.flags())] = Offence(
                f"{type(event).__name__} published to a rover while OffboardControlMode sets "
                f"{flags_text(mode)}: actuator setpoints need direct_actuator as the only true "
                "flag, otherwise the rover modules write the actuators too",
                Severity.ERROR,
            )
        self.episodes.update("OFB506", "actuators", event.t, event.where, offences)

    def finish(self, t_end: float) -> None:
        self.episodes.finish()
