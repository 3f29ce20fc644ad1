"""OFB404 (heuristic): setpoints that look like ENU/FLU where PX4 expects NED/FRD.

Two signs of a frame mix-up that a real flight almost never shows:

* the first sizeable vertical command after arming (or of the recording, where arming is not
  recorded) points down: a position more than ``z_m`` below the start point (``z`` > 0 in NED)
  or a vertical velocity above ``vz_mps`` (``vz`` > 0 is descending): a climb written in ENU;
* a multicopter attitude or rates setpoint whose ``thrust_body`` z is above ``thrust_z``
  (FRD thrust points up as negative z): thrust written in FLU.
"""

from __future__ import annotations

import math
from itertools import repeat
from operator import attrgetter, gt, itemgetter

from fuzzoff.checks._external import Episodes, external_only, from_external
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import (
    AttitudeSetpoint,
    Event,
    RatesSetpoint,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.gate import GateTransition

MAV_FRAME_LOCAL_NED = 1
MAV_FRAME_BODY_NED = 8
IGNORE_Z = 4
IGNORE_V = 8 | 16 | 32
IGNORE_VZ = 32

_THRUST_Z = attrgetter("thrust_body")
_Z = itemgetter(2)


def vertical_command(event: Event) -> tuple[float, float]:
    """(z position, z velocity) the setpoint commands; NaN where it commands none."""
    if isinstance(event, TrajectorySetpoint):
        return event.position[2], event.velocity[2]
    if isinstance(event, SetPositionTargetLocal):
        z = math.nan
        vz = math.nan
        if event.coordinate_frame == MAV_FRAME_LOCAL_NED:
            z = math.nan if event.type_mask & IGNORE_Z else event.position[2]
            vz = math.nan if event.type_mask & IGNORE_VZ else event.velocity[2]
        elif event.coordinate_frame == MAV_FRAME_BODY_NED and not event.type_mask & IGNORE_V:
            vz = event.velocity[2]
        return z, vz
    return math.nan, math.nan


class FrameConventionSuspect(Check):
    codes = ("OFB404",)
    wants = (
        TrajectorySetpoint,
        SetPositionTargetLocal,
        AttitudeSetpoint,
        RatesSetpoint,
        VehicleStatus,
        GateTransition,
    )

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.z_m = float(ctx.option("OFB404", "z_m"))
        self.vz_mps = float(ctx.option("OFB404", "vz_mps"))
        self.thrust_z = float(ctx.option("OFB404", "thrust_z"))
        self.thrust = Episodes(ctx, "OFB404")
        self.takeoff_pending = True
        """Waiting for the first sizeable vertical command since the vehicle was on the ground."""
        self.armed: bool | None = None
        """The last recorded arming state (None: not recorded yet)."""
        self.thrust_types = (AttitudeSetpoint, RatesSetpoint)
        self.takeoff_types = (TrajectorySetpoint, SetPositionTargetLocal)

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: no external setpoint that could be the first vertical command (else
        replay), and no thrust above the threshold: every thrust setpoint is then ``good``, which
        only closes (reports) an open stretch at the first message of its kind."""
        if self.takeoff_pending and external_only(self.ctx, batch.of(self.takeoff_types)):
            self.replay(batch)
            return
        if self.ctx.profile.vehicle != "mc":
            return
        thrust = external_only(self.ctx, batch.of(self.thrust_types))
        if not thrust:
            return
        if any(map(gt, map(_Z, map(_THRUST_Z, thrust)), repeat(self.thrust_z))):
            self.replay(batch)  # a bad one (or an infinite z, which is good: on_event decides)
            return
        if self.thrust.open:
            for kind in dict.fromkeys(event.kind for event in thrust):
                self.thrust.good(kind)

    def on_event(self, event: Event) -> None:
        if isinstance(event, VehicleStatus) and event.armed is not None:
            if not event.armed and self.armed is not False:
                self.takeoff_pending = True  # on the ground (again)
            elif event.armed and self.armed is None:
                self.takeoff_pending = False  # the recording starts in flight
            self.armed = event.armed
            return
        if isinstance(event, GateTransition):
            if event.what == "disarmed" and self.armed is None:
                self.takeoff_pending = True
            return
        # from_external last: after take-off the usual setpoint needs no further look
        if isinstance(event, (AttitudeSetpoint, RatesSetpoint)):
            if from_external(self.ctx, event):
                self._thrust(event)
        elif self.takeoff_pending and from_external(self.ctx, event):
            self._takeoff(event)

    def _takeoff(self, event: Event) -> None:
        z, vz = vertical_command(event)
        down = (math.isfinite(z) and z > self.z_m) or (math.isfinite(vz) and vz > self.vz_mps)
        up = (math.isfinite(z) and z < -self.z_m) or (math.isfinite(vz) and vz < -self.vz_mps)
        if not (down or up):
            return  # small commands (a zero setpoint before the switch) decide nothing
        self.takeoff_pending = False
        if not down:
            return
        what = f"z = {z:g} m" if math.isfinite(z) and z > self.z_m else f"vz = {vz:g} m/s"
        self.ctx.report(
            "OFB404",
            f"the first vertical command since the vehicle was on the ground is {what}, "
            "downwards in NED: looks like a climb written in ENU (up positive); PX4 expects "
            f"NED (thresholds z_m = {self.z_m:g}, vz_mps = {self.vz_mps:g})",
            event.t,
            event.where,
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
            f"in FLU (up positive); PX4 expects negative z for lift (threshold {self.thrust_z:g})",
        )

    def finish(self, t_end: float) -> None:
        self.thrust.close_all()
