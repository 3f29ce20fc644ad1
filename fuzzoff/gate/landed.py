"""Is the vehicle on the ground, as PX4 asks when it judges a disarm request (gate.md#seen-on-px4)?

Commander refuses a disarm that is not forced (param2 21196) unless the land detector says
``landed`` or ``maybe_landed`` (or the vehicle drives on the ground): "Disarming denied: not
landed", ack 1 (seen on 1.15.4 and 1.18.0-alpha1 SITL). The recording says so where it has the
land detector (ULog ``vehicle_land_detected``, MAVLink ``EXTENDED_SYS_STATE``). Elsewhere the
model assumes the vehicle is on the ground until it sees evidence of a take-off, and airborne
from then until it is disarmed:

* a recorded take-off mode (AUTO_TAKEOFF, AUTO_VTOL_TAKEOFF) while armed;
* armed in OFFBOARD with a setpoint that climbs (a local NED position 0.5 m or more above the
  origin, or an upward velocity) for ``CLIMB_S``: PX4 detects a take-off 1-2 s after such a
  setpoint starts (1.9 s on 1.18.0-alpha1 SITL);
* still armed ``COM_DISARM_PRFLT`` (10 s) after arming: PX4 disarms a vehicle that does not
  take off by then, so one still armed has left the ground.

Every answer carries the reason, so the timeline says what was recorded and what assumed.
"""

from __future__ import annotations

import math

from fuzzoff.events import (
    LandDetected,
    SetPositionTargetLocal,
    TrajectorySetpoint,
)
from fuzzoff.type_mask import VZ_IGNORE, Z_IGNORE

CLIMB_S = 2.0
"""How long a climb setpoint must be flown, armed in OFFBOARD, to count as a take-off."""
CLIMB_Z_M = -0.5
"""A NED position setpoint at or above this height (z at or below -0.5 m) climbs."""
CLIMB_VZ_MS = -0.2
"""A NED velocity setpoint at or below this (upward) climbs."""
TAKEOFF_NAV_STATES = frozenset({17, 22})
"""AUTO_TAKEOFF, AUTO_VTOL_TAKEOFF."""

_LOCAL_NED = 1
_BODY_NED = 8


def climbs(event: SetPositionTargetLocal | TrajectorySetpoint) -> bool:
    """Does this setpoint ask to leave the ground (NED: up is negative z)?"""
    if isinstance(event, TrajectorySetpoint):
        z, vz = event.position[2], event.velocity[2]
        return (math.isfinite(z) and z <= CLIMB_Z_M) or (math.isfinite(vz) and vz <= CLIMB_VZ_MS)
    mask, frame = event.type_mask, event.coordinate_frame
    if frame == _LOCAL_NED and not mask & Z_IGNORE and event.position[2] <= CLIMB_Z_M:
        return True
    return (
        frame in (_LOCAL_NED, _BODY_NED)
        and not mask & VZ_IGNORE
        and event.velocity[2] <= CLIMB_VZ_MS
    )


class LandedState:
    """The recorded land detector, else the take-off evidence, for one vehicle."""

    def __init__(self, preflight_disarm_s: float) -> None:
        self.preflight_disarm_s = preflight_disarm_s
        self.recorded: bool | None = None
        self.recorded_since = -math.inf
        """When the recorded land detector last changed its verdict."""
        self.recorded_ever = False
        self.evidence: str | None = None
        """Why the vehicle is taken as airborne (no land detector recorded), or None."""
        self.armed_at: float | None = None
        self.climb_since: float | None = None
        self.watching = False
        """Do setpoints still matter (no land detector recorded, armed, no evidence yet)? An
        attribute, not a property: the model asks it on every setpoint."""

    def _watch(self) -> None:
        self.watching = (
            not self.recorded_ever and self.armed_at is not None and self.evidence is None
        )

    def land_detected(self, event: LandDetected) -> None:
        if event.landed is None:
            return
        if event.landed != self.recorded:
            self.recorded_since = event.t
        self.recorded = event.landed
        self.recorded_ever = True
        self.watching = False

    def armed(self, t: float) -> None:
        if self.armed_at is None:
            self.armed_at = t
            self._watch()

    def disarmed(self) -> None:
        self.armed_at = None
        self.climb_since = None
        self.evidence = None
        self._watch()

    def mode(self, t: float, nav: int | None) -> None:
        if nav in TAKEOFF_NAV_STATES and self.armed_at is not None and self.evidence is None:
            self.evidence = f"recorded in a take-off mode at {t:.2f} s"
            self._watch()

    def setpoint(self, t: float, climbing: bool) -> None:
        """A setpoint flown armed in OFFBOARD (``climbing``: ``climbs`` said so)."""
        if self.evidence is not None:
            return
        if not climbing:
            self.climb_since = None
        elif self.climb_since is None:
            self.climb_since = t

    def landed(self, t: float) -> tuple[bool, str]:
        """PX4's ``landed or maybe_landed`` at ``t`` and why the model says so."""
        if self.recorded_ever:
            state = "landed" if self.recorded else "not landed"
            return bool(self.recorded), f"land detector: {state} since {self.recorded_since:.2f} s"
        if (
            self.evidence is None
            and self.climb_since is not None
            and t - self.climb_since >= (CLIMB_S)
        ):
            self.evidence = (
                f"armed in OFFBOARD with a climb setpoint since {self.climb_since:.2f} s"
            )
        if (
            self.evidence is None
            and self.armed_at is not None
            and self.preflight_disarm_s > 0.0
            and t - self.armed_at >= self.preflight_disarm_s
        ):
            self.evidence = (
                f"still armed {t - self.armed_at:.1f} s after arming: PX4 disarms a vehicle "
                f"that has not taken off within COM_DISARM_PRFLT {self.preflight_disarm_s:g} s"
            )
        if self.evidence is not None:
            self.watching = False
            return False, f"assumed airborne ({self.evidence}; no land detector recorded)"
        return True, "assumed on the ground (no take-off seen, no land detector recorded)"
