"""OFB510 (rover-setpoint-overwritten-in-offboard): the rover setpoints PX4 itself rewrites.

In OFFBOARD an Ackermann rover's offboard mode (PX4 1.17+, ``AckermannOffboardMode`` of
``src/modules/rover_ackermann``) converts the latest ``TrajectorySetpoint`` into rover setpoints
every cycle: with the ``position`` flag a ``RoverPositionSetpoint``, with ``velocity`` a
``RoverSpeedSetpoint`` and a ``RoverAttitudeSetpoint``. It does so whether or not a
``TrajectorySetpoint`` was ever published (then from zeros), so the companion's own setpoints of
those levels are overwritten: seen on PX4 1.17.0 and the 1.18 head (corpora/ros2bridge,
``rover_position``, ``rover_speed_*``), where the rover stood still. What counts as "published"
is as for OFB502: the last message of each rover setpoint topic within ``window_s`` before an
``OffboardControlMode``, carrying a value.
"""

from __future__ import annotations

from fuzzoff.checks._episodes import Episodes, Offence
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.checks.rover import logged_only
from fuzzoff.events import (
    ControlMode,
    Event,
    RoverAttitudeSetpoint,
    RoverPositionSetpoint,
    RoverSpeedSetpoint,
    TrajectorySetpoint,
)
from fuzzoff.tables import rover as tr

REWRITTEN: dict[str, tuple[str, ...]] = {
    "position": (tr.POSITION,),
    "velocity": (tr.SPEED, tr.ATTITUDE),
}
"""The first ``OffboardControlMode`` flag -> the rover setpoints the offboard mode writes."""


class RoverSetpointOverwrittenInOffboard(Check):
    """OFB510: one finding per stretch of control modes whose rover setpoints PX4 overwrites."""

    codes = ("OFB510",)
    wants = (
        ControlMode,
        RoverPositionSetpoint,
        RoverSpeedSetpoint,
        RoverAttitudeSetpoint,
        TrajectorySetpoint,
    )

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.window = float(ctx.option("OFB510", "window_s"))
        self.last: dict[str, float] = {}
        """Setpoint kind -> the time of its last message sent with a value."""
        logged_only(ctx, self.codes, (tr.POSITION, tr.SPEED, tr.ATTITUDE))

    def on_event(self, event: Event) -> None:
        if event.origin != "sent":
            return
        if isinstance(event, TrajectorySetpoint):
            self.last[event.kind] = event.t
            return
        if not isinstance(event, ControlMode):
            if tr.has_value(event):
                self.last[event.kind] = event.t
            return
        flag = event.first_flag()
        recent = {k for k, t in self.last.items() if event.t - t <= self.window}
        rewritten = [k for k in REWRITTEN.get(flag or "", ()) if k in recent]
        if not self.ctx.in_offboard or not rewritten or TrajectorySetpoint.kind in recent:
            # the deprecated TrajectorySetpoint drives it (OFB501 speaks), or nothing to judge
            self.episodes.clear("OFB510")
            return
        names = tr.names(frozenset(rewritten))
        offence = Offence(
            f"{names} published under the OffboardControlMode {flag} flag in OFFBOARD: PX4"
            f" {self.ctx.profile.px4}'s Ackermann offboard mode rewrites them every cycle from"
            " TrajectorySetpoint (zeros when none is published), so the rover does not follow"
            " them (it stood still on PX4 1.17.0 and 1.18); in OFFBOARD drive it with"
            " RoverThrottleSetpoint + RoverSteeringSetpoint (thrust_and_torque) or the"
            " deprecated TrajectorySetpoint",
            short=f"{names} under '{flag}': PX4 rewrites them from TrajectorySetpoint",
        )
        self.episodes.update("OFB510", "rover", event.t, event.where, {flag or "": offence})

    def finish(self, t_end: float) -> None:
        self.episodes.finish()
