"""Which controllers run in offboard (gate.md#control-mode to #rover).

* ``control_flags``: ``offboard_control_mode`` -> ``vehicle_control_mode`` flags (section 7);
* ``mc_axes``: what the multicopter position controller does with a trajectory setpoint, per
  axis (section 8);
* ``describe``: one line naming what runs, per vehicle type (sections 8-10).

Trajectory content is passed as a 9-bit "axes" mask: bits 0-2 position x/y/z finite, 3-5
velocity, 6-8 acceleration.
"""

from __future__ import annotations

import math

from fuzzoff.events import TrajectorySetpoint
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.ocm import (
    ACCELERATION,
    ACTUATOR,
    ATTITUDE,
    BODY_RATE,
    DIRECT_ACTUATOR,
    FLAG_NAMES,
    POSITION,
    THRUST_AND_TORQUE,
    VELOCITY,
    first_flag,
)
from fuzzoff.releases import Release

LAST_VALID_S = 0.2
"""1.16+: an invalid setpoint reuses the last valid one if it is younger than this (8)."""


def axes_of(sp: TrajectorySetpoint) -> int:
    """The 9-bit per-axis finiteness of a trajectory setpoint (position, velocity, acceleration)."""
    isf = math.isfinite
    p, v, a = sp.position, sp.velocity, sp.acceleration
    return (
        isf(p[0])
        | isf(p[1]) << 1
        | isf(p[2]) << 2
        | isf(v[0]) << 3
        | isf(v[1]) << 4
        | isf(v[2]) << 5
        | isf(a[0]) << 6
        | isf(a[1]) << 7
        | isf(a[2]) << 8
    )


_BASE: dict[int, tuple[str, ...]] = {
    POSITION: (
        "position",
        "velocity",
        "altitude",
        "climb_rate",
        "acceleration",
        "attitude",
        "rates",
    ),
    VELOCITY: ("velocity", "altitude", "climb_rate", "acceleration", "attitude", "rates"),
    ACCELERATION: ("acceleration", "attitude", "rates"),
    ATTITUDE: ("attitude", "rates"),
    BODY_RATE: ("rates",),
}


def control_flags(release: Release, mask: int) -> tuple[str, ...]:
    """The ``flag_control_*`` names enabled in OFFBOARD for this flag mask (section 7)."""
    first = first_flag(mask)
    if not release.control_mode_flags:
        return _legacy_flags(mask)
    if first in (ACTUATOR, THRUST_AND_TORQUE):
        return ("allocation",) if release.allocation_flag and first == THRUST_AND_TORQUE else ()
    if first in (DIRECT_ACTUATOR, 0):
        return ()
    if release.setpoint_types_control_mode:
        if first == POSITION:
            return (
                "allocation",
                "rates",
                "attitude",
                "altitude",
                "velocity",
                "position",
                "climb_rate",
            )
        if first == VELOCITY:
            return ("allocation", "rates", "attitude", "altitude", "velocity", "climb_rate")
        if first == ACCELERATION:
            return ("allocation", "rates", "attitude", "velocity")
        return ("allocation", *_BASE[first])
    flags = _BASE[first]
    if release.allocation_flag:
        flags = (*flags, "allocation")
    return flags


def _legacy_flags(mask: int) -> tuple[str, ...]:
    """legacy ``set_control_mode``: enabling acceleration disables position and velocity."""
    pos, vel, acc = bool(mask & POSITION), bool(mask & VELOCITY), bool(mask & ACCELERATION)
    out: list[str] = []
    if mask & BODY_RATE or mask & ATTITUDE or pos or vel or acc:
        out.append("rates")
    if mask & ATTITUDE or pos or vel or acc:
        out.append("attitude")
    if acc:
        out.append("acceleration")
    if (vel or pos) and not acc:
        out += ["velocity", "climb_rate", "altitude"]
    if pos and not acc:
        out.append("position")
    return tuple(out)


_POSITION_LOOPS = ("position", "velocity", "acceleration", "altitude", "climb_rate")


def position_control(release: Release, mask: int) -> bool:
    """Does this OCM switch the (multicopter) position controller on?"""
    flags = control_flags(release, mask)
    return any(
        f in flags for f in ("position", "velocity", "acceleration", "altitude", "climb_rate")
    )


def mc_axes(axes: int, est: Estimates) -> str | None:
    """Why PositionControl rejects this setpoint (``_inputValid``, section 8), or None."""
    for i, name in enumerate("xyz"):
        if not axes & (1 << i | 1 << (i + 3) | 1 << (i + 6)):
            return f"axis {name} has no finite position, velocity or acceleration"
    for shift, what in ((0, "position"), (3, "velocity"), (6, "acceleration")):
        x, y = bool(axes & (1 << shift)), bool(axes & (2 << shift))
        if x != y:
            return f"{what} x and y are not both finite or both NaN"
    if axes & 0b111 and not est.local_position:
        return "position setpoint without a position estimate"
    if axes & 0b111000 and not est.local_velocity:
        return "velocity setpoint without a velocity estimate"
    return None


def mc_axes_text(axes: int) -> str:
    """``x,y position; z velocity`` style summary of which loop runs per axis."""
    parts: dict[str, list[str]] = {}
    for i, name in enumerate("xyz"):
        if axes & (1 << i):
            loop = "position"
        elif axes & (1 << (i + 3)):
            loop = "velocity"
        elif axes & (1 << (i + 6)):
            loop = "acceleration"
        else:
            loop = "nothing"
        parts.setdefault(loop, []).append(name)
    return "; ".join(f"{','.join(axes_)} {loop}" for loop, axes_ in parts.items())


def failsafe_setpoint(est: Estimates, land_speed: float) -> str:
    """What ``generateFailsafeSetpoint`` holds (section 8)."""
    if est.local_velocity:
        return "failsafe setpoint: hold (zero velocity)"
    return f"failsafe setpoint: blind descent at {land_speed:g} m/s (MPC_LAND_SPEED)"


_ROVER_TABLE: dict[str, dict[int, str]] = {
    "rover-ackermann": {
        POSITION: "RoverPositionSetpoint from TrajectorySetpoint.position",
        VELOCITY: "RoverSpeedSetpoint + RoverAttitudeSetpoint from the velocity direction",
        ATTITUDE: "nothing (yaw unsupported on Ackermann)",
        BODY_RATE: "nothing (yaw rate unsupported on Ackermann)",
    },
    "rover-differential": {
        POSITION: "RoverPositionSetpoint from TrajectorySetpoint.position",
        VELOCITY: "RoverSpeedSetpoint + RoverAttitudeSetpoint from the velocity direction",
        ATTITUDE: "RoverAttitudeSetpoint from yaw",
        BODY_RATE: "RoverRateSetpoint from yawspeed",
    },
    "rover-mecanum": {
        POSITION: "RoverPositionSetpoint (+ yaw/yawspeed if attitude/body_rate also set)",
        VELOCITY: "body-frame speed x/y + attitude from the velocity direction",
        ATTITUDE: "RoverAttitudeSetpoint from yaw",
        BODY_RATE: "RoverRateSetpoint from yawspeed",
    },
}


def describe(release: Release, vehicle: str, mask: int) -> tuple[str, str, bool]:
    """(text, spec section, unverified) naming what runs in OFFBOARD for this OCM."""
    first = first_flag(mask)
    flags = control_flags(release, mask)
    chain = ", ".join(flags) if flags else "no controller"
    name = FLAG_NAMES.get(first, "no flag")
    if vehicle.startswith("rover"):
        if release.rover_drive_modes:
            what = _ROVER_TABLE[vehicle].get(first, "no rover setpoint generated")
            return f"rover offboard ({name}): {what}; controllers {chain}", "10", False
        return (
            f"rover offboard ({name}): controllers {chain} (rover per-flag behaviour "
            f"before main not tabulated)",
            "10",
            True,
        )
    if vehicle == "fw":
        if first == POSITION:
            return f"fixed-wing offboard position control ({chain})", "9", False
        if first == VELOCITY:
            return (
                f"fixed-wing: velocity flag without position: offboard branch not taken ({chain})",
                "9",
                True,
            )
        return f"fixed-wing offboard {name}: {chain}", "9", False
    unverified = vehicle == "vtol" or release.old_code_unverified
    return f"offboard {name}: {chain}", "7", unverified
