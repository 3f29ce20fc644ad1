"""OFB404 (heuristic): setpoints that look like ENU/FLU where PX4 expects NED/FRD.

Three signs of a frame mix-up that a real flight almost never shows, each an error because the
vehicle would fly into the ground (or push into it instead of climbing):

* from the ground, the first sizeable vertical command points down: a position more than ``z_m``
  below the vehicle (``z`` larger than the vehicle's local z, NED) or a vertical velocity above
  ``vz_mps`` (``vz`` > 0 is descending): a climb written in ENU;
* in the air, a position target more than ``z_m`` below the ground the vehicle took off from: a
  height written in ENU (a descent by velocity is an ordinary command there, so only positions
  are judged).

The vehicle's height is its estimate's local z where the recording has it (``VehiclePosition``:
ULog and ROS 2 ``vehicle_local_position``, MAVLink LOCAL_POSITION_NED, MAVROS
``local_position/pose``): an estimator's z drifts on the ground (PX4 1.15's SIH to +1.8 m), and a
client that sends its current position before the takeoff sends that z. Where the recording
has no position, the local origin (z = 0) stands for both;
* a multicopter attitude or rates setpoint whose ``thrust_body`` z is above ``thrust_z`` (FRD
  thrust points up as negative z): thrust written in FLU.

"On the ground" is the vehicle disarmed (recorded, else as the gate model has it), or the start
of a recording whose arming is not recorded. A takeoff in any mode leaves it: the vehicle armed
in a mode in which it can take off (auto takeoff, a mission, a pilot mode) or a takeoff command;
a recording that starts armed starts in the air. Only the external controller's setpoints are
judged: as sent, or a ULog's logged copy while the recorded status says OFFBOARD (PX4's own
flight tasks write ``trajectory_setpoint`` in its other modes, and an ack of a switch is not yet
the switch: PX4 1.16 and 1.17 ack one first from the receiver).
"""

from __future__ import annotations

import math
from itertools import repeat
from operator import attrgetter, gt, itemgetter
from typing import Literal

from fuzzoff.checks._external import Episodes, external_only, from_external
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import (
    NAV_STATE_OFFBOARD,
    AttitudeSetpoint,
    Command,
    Event,
    RatesSetpoint,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehiclePosition,
    VehicleStatus,
)
from fuzzoff.gate import GateTransition
from fuzzoff.mavlink_ids import (
    MAV_CMD_NAV_TAKEOFF,
    MAV_CMD_NAV_VTOL_TAKEOFF,
    MAV_FRAME_BODY_NED,
    MAV_FRAME_LOCAL_NED,
)
from fuzzoff.type_mask import VELOCITY_BITS, VZ_IGNORE, Z_IGNORE

TAKEOFF_MODES = frozenset(
    {
        0,  # MANUAL
        1,  # ALTCTL
        2,  # POSCTL
        3,  # AUTO_MISSION
        6,  # POSITION_SLOW
        10,  # ACRO
        15,  # STAB
        16,  # RATTITUDE
        17,  # AUTO_TAKEOFF
        19,  # AUTO_FOLLOW_TARGET
        21,  # ORBIT
        22,  # AUTO_VTOL_TAKEOFF
        *range(23, 31),  # EXTERNAL1-8
    }
)
"""nav_states in which an armed vehicle can have taken off (by itself or by a pilot). Hold,
Return, Land, Descend and Termination do not take off."""

Place = Literal["ground", "air"]

_THRUST_Z = attrgetter("thrust_body")
_POSITION_Z = itemgetter(2)
_POSITION = attrgetter("position")
_ORIGIN = attrgetter("origin")


def vertical_command(event: Event) -> tuple[float, float]:
    """(z position, z velocity) the setpoint commands; NaN where it commands none."""
    if isinstance(event, TrajectorySetpoint):
        return event.position[2], event.velocity[2]
    if isinstance(event, SetPositionTargetLocal):
        z = math.nan
        vz = math.nan
        if event.coordinate_frame == MAV_FRAME_LOCAL_NED:
            z = math.nan if event.type_mask & Z_IGNORE else event.position[2]
            vz = math.nan if event.type_mask & VZ_IGNORE else event.velocity[2]
        elif event.coordinate_frame == MAV_FRAME_BODY_NED and not event.type_mask & VELOCITY_BITS:
            vz = event.velocity[2]
        return z, vz
    return math.nan, math.nan


def _position_z(event: Event) -> float:
    return vertical_command(event)[0]


class FrameConventionSuspect(Check):
    codes = ("OFB404",)
    wants = (
        TrajectorySetpoint,
        SetPositionTargetLocal,
        AttitudeSetpoint,
        RatesSetpoint,
        VehicleStatus,
        VehiclePosition,
        Command,
        GateTransition,
    )

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.z_m = float(ctx.option("OFB404", "z_m"))
        self.vz_mps = float(ctx.option("OFB404", "vz_mps"))
        self.thrust_z = float(ctx.option("OFB404", "thrust_z"))
        self.thrust = Episodes(ctx, "OFB404")
        self.below = Episodes(ctx, "OFB404")
        self.where: Place = "ground"
        """On the ground (the first sizeable vertical command is judged) or in the air (or
        maybe: a position below the origin is judged)."""
        self.decided = False
        """On the ground: the first sizeable vertical command has been judged."""
        self.flagged = False
        """A climb written in ENU was reported since the vehicle was last on the ground: the
        same stream below the origin is that finding, not a new one."""
        self.armed: bool | None = None
        """The last recorded arming state (None: not recorded yet)."""
        self.status_offboard = False
        """The last recorded status says OFFBOARD (a ULog's logged setpoints count only then)."""
        self.vehicle_z: float | None = None
        """The vehicle's newest valid local z (NED), where the recording has its position."""
        self.ground_z: float | None = None
        """Its local z when last on the ground: where a target in the air is below ground."""
        self.thrust_types = (AttitudeSetpoint, RatesSetpoint)
        self.vertical_types = (TrajectorySetpoint, SetPositionTargetLocal)

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: no external position or velocity setpoint that could be judged (on the
        ground, the first sizeable command; in the air, none below the origin, and then every
        one only closes an open stretch at its first message), and no thrust above the
        threshold (every thrust setpoint is then ``good``: the same)."""
        vertical = self._mine(batch.of(self.vertical_types))
        if vertical:
            if self.where == "ground" and not self.decided:
                self.replay(batch)
                return
            if self.where == "air" and not self.flagged:
                if self._any_below(vertical, self._ground() + self.z_m):
                    self.replay(batch)
                    return
                if self.below.open:
                    for kind in dict.fromkeys(event.kind for event in vertical):
                        self.below.good(kind)
        if self.ctx.profile.vehicle != "mc":
            return
        thrust = self._mine(batch.of(self.thrust_types))
        if not thrust:
            return
        if any(map(gt, map(_POSITION_Z, map(_THRUST_Z, thrust)), repeat(self.thrust_z))):
            self.replay(batch)  # a bad one (or an infinite z, which is good: on_event decides)
            return
        if self.thrust.open:
            for kind in dict.fromkeys(event.kind for event in thrust):
                self.thrust.good(kind)

    def _any_below(self, events: list[Event], limit: float) -> bool:
        """Could any of ``events`` be a position target below ``limit`` (NaN never is)? The
        raw z of every message first (a MAVLink mask or frame only takes positions away)."""
        raw = map(_POSITION_Z, map(_POSITION, events))
        if not any(map(gt, raw, repeat(limit))):
            return False
        return any(map(gt, map(_position_z, events), repeat(limit)))

    def _ground(self) -> float:
        """The ground's local z: where the vehicle last was on the ground, else the origin.

        A target is judged below the vehicle or the ground only when it is below the local
        origin too: an estimate that drifted upwards on the ground (PX4 1.14's airplane read
        0.56 m up at rest) would otherwise make a setpoint at the origin, z = 0, look like ENU."""
        return 0.0 if self.ground_z is None else self.ground_z

    def _mine(self, events: list[Event]) -> list[Event]:
        """The external controller's messages among a run's: as sent, or logged while the
        recorded status says OFFBOARD."""
        external = external_only(self.ctx, events)
        if not external or self.status_offboard or set(map(_ORIGIN, external)) == {"sent"}:
            return external
        return [e for e in external if e.origin == "sent"]

    def _is_mine(self, event: Event) -> bool:
        if event.origin != "sent" and not self.status_offboard:
            return False
        return from_external(self.ctx, event)

    def on_event(self, event: Event) -> None:
        if isinstance(event, VehicleStatus):
            self._status(event)
            return
        if isinstance(event, VehiclePosition):
            if math.isfinite(event.z):
                self.vehicle_z = event.z
                if self.where == "ground":
                    self.ground_z = event.z
            return
        if isinstance(event, Command):
            if event.command in (MAV_CMD_NAV_TAKEOFF, MAV_CMD_NAV_VTOL_TAKEOFF):
                self._took_off()
            return
        if isinstance(event, GateTransition):
            if event.what == "disarmed" and self.armed is None:
                self._on_ground()
            return
        if not self._is_mine(event):
            return
        if isinstance(event, (AttitudeSetpoint, RatesSetpoint)):
            self._thrust(event)
        elif self.where == "ground":
            if not self.decided:
                self._from_ground(event)
        elif not self.flagged:
            self._in_the_air(event)

    def _status(self, event: VehicleStatus) -> None:
        if event.nav_state is not None:
            self.status_offboard = event.nav_state == NAV_STATE_OFFBOARD
        if event.armed is None:
            return
        if not event.armed:
            if self.armed is not False:
                self._on_ground()
        elif self.armed is None and self.where == "ground" and not self.decided:
            self._took_off()  # the recording starts armed: in flight
        elif event.nav_state in TAKEOFF_MODES:
            self._took_off()
        self.armed = event.armed

    def _on_ground(self) -> None:
        self.below.close_all()
        if self.where == "ground":
            # It never left the ground (the first status confirms where a recording starts, or
            # PX4 disarmed a vehicle pushing into the ground): the same stretch, judged once.
            return
        self.where, self.decided, self.flagged = "ground", False, False

    def _took_off(self) -> None:
        self.where = "air"

    def _from_ground(self, event: Event) -> None:
        z, vz = vertical_command(event)
        here = 0.0 if self.vehicle_z is None else self.vehicle_z
        below = math.isfinite(z) and z > max(here, 0.0) + self.z_m
        down = below or (math.isfinite(vz) and vz > self.vz_mps)
        up = (math.isfinite(z) and z < here - self.z_m) or (math.isfinite(vz) and vz < -self.vz_mps)
        if not (down or up):
            return  # small commands (the vehicle's own position before the switch) decide nothing
        self.decided = True
        if not down:
            self.where = "air"  # it climbs: what follows is judged as in the air
            return
        self.flagged = True
        if not below:
            what = short = f"vz = {vz:g} m/s, downwards in NED"
        elif self.vehicle_z is None:
            what = f"z = {z:g} m, below the local origin (the recording has no vehicle position)"
            short = f"z = {z:g} m, below the origin"
        else:
            what = f"z = {z:g} m, {z - here:.2f} m below the vehicle (its local z = {here:g} m)"
            short = f"z = {z:g} m, {z - here:.2f} m below the vehicle"
        self.ctx.report(
            "OFB404",
            f"the first vertical command since the vehicle was on the ground is {what}: looks "
            "like a climb written in ENU (up positive); PX4 expects NED and keeps the vehicle "
            "on the ground, pushing into it "
            f"(thresholds z_m = {self.z_m:g}, vz_mps = {self.vz_mps:g})",
            event.t,
            event.where,
            short=f"first vertical command from the ground is {short}: a climb in ENU?",
        )

    def _in_the_air(self, event: Event) -> None:
        z = vertical_command(event)[0]
        ground = self._ground()
        if not (math.isfinite(z) and z > max(ground, 0.0) + self.z_m):
            self.below.good(event.kind)
            return
        if self.ground_z is None:
            where = short = "below the local origin"
        else:
            where = (
                f"{z - ground:.2f} m below the ground the vehicle took off from (z = {ground:g} m)"
            )
            short = f"{z - ground:.2f} m below the ground it took off from"
        self.below.bad(
            event.kind,
            event.t,
            event.where,
            f"position target z = {z:g} m, {where}, after a takeoff (or in a mode that takes "
            "off) since the vehicle was last on the ground: looks like a height written in ENU "
            "(up positive); PX4 expects NED and flies the vehicle down towards it, into the "
            f"ground (threshold z_m = {self.z_m:g})",
            short=f"position target z = {z:g} m in the air, {short}: ENU?",
        )

    def _thrust(self, event: AttitudeSetpoint | RatesSetpoint) -> None:
        if self.ctx.profile.vehicle != "mc":
            return
        tz = event.thrust_body[2]
        if not (math.isfinite(tz) and tz > self.thrust_z):
            self.thrust.good(event.kind)
            return
        self.thrust.bad(
            event.kind,
            event.t,
            event.where,
            f"multicopter thrust_body z = {tz:g} points down in FRD: looks like thrust written "
            "in FLU (up positive); PX4 expects negative z for lift, so the vehicle gets no lift "
            f"and falls, or stays on the ground (threshold {self.thrust_z:g})",
        )

    def finish(self, t_end: float) -> None:
        self.thrust.close_all()
        self.below.close_all()
