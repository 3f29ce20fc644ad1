"""The frame arithmetic MAVROS applies between ROS (ENU / FLU) and PX4 (NED / FRD).

MAVROS's ``ftf`` library (frame_tf) defines two static rotations and applies them the same way
in MAVROS 1 and MAVROS 2 (formats.md section 6.1):

* ENU <-> NED for vectors is the reflection ``(x, y, z) -> (y, x, -z)``; for orientations the
  quaternion is pre-multiplied by ``NED_ENU_Q`` (roll pi, yaw pi/2);
* base_link (FLU) <-> aircraft (FRD) for vectors is ``(x, y, z) -> (x, -y, -z)``; for
  orientations the quaternion is post-multiplied by ``AIRCRAFT_BASELINK_Q`` (roll pi).

All are their own inverse (up to quaternion sign), which the writer uses for the way back.
Quaternions are ``(w, x, y, z)`` tuples, as in MAVLink and fuzzoff's events.
"""

from __future__ import annotations

import math

from fuzzoff.events import Quat, Vec3


def quat_mul(a: Quat, b: Quat) -> Quat:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def quat_conj(q: Quat) -> Quat:
    return (q[0], -q[1], -q[2], -q[3])


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> Quat:
    """Z-Y-X (yaw, then pitch, then roll) composition, as ``ftf::quaternion_from_rpy``."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )


def quat_yaw(q: Quat) -> float:
    """Yaw of a quaternion, in (-pi, pi] (``ftf::quaternion_get_yaw``)."""
    w, x, y, z = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


NED_ENU_Q: Quat = quat_from_rpy(math.pi, 0.0, math.pi / 2)
AIRCRAFT_BASELINK_Q: Quat = quat_from_rpy(math.pi, 0.0, 0.0)


def enu_to_ned(v: Vec3) -> Vec3:
    """ENU <-> NED for a vector (its own inverse)."""
    return (v[1], v[0], -v[2])


def flu_to_frd(v: Vec3) -> Vec3:
    """base_link (FLU) <-> aircraft (FRD) for a vector (its own inverse)."""
    return (v[0], -v[1], -v[2])


def orientation_enu_to_ned(q: Quat) -> Quat:
    """base_link-in-ENU -> aircraft-in-NED (MAVROS: enu_ned(baselink_aircraft(q)))."""
    return quat_mul(quat_mul(NED_ENU_Q, q), AIRCRAFT_BASELINK_Q)


def orientation_ned_to_enu(q: Quat) -> Quat:
    """The inverse of ``orientation_enu_to_ned``."""
    return quat_mul(quat_mul(quat_conj(NED_ENU_Q), q), quat_conj(AIRCRAFT_BASELINK_Q))


def yaw_enu_to_ned(yaw: float) -> float:
    """ENU yaw -> NED yaw as MAVROS computes it for ``setpoint_raw``: pi/2 - yaw, wrapped.

    MAVROS builds a yaw-only quaternion, rotates it and extracts the yaw again, which wraps the
    result into (-pi, pi]; the closed form gives the same number (tests check both agree).
    """
    return math.atan2(math.cos(yaw), math.sin(yaw))  # = wrap(pi/2 - yaw)


def yaw_flu_to_frd(yaw: float) -> float:
    """Body-frame yaw (FLU -> FRD): the yaw changes sign (wrapped)."""
    return math.atan2(-math.sin(yaw), math.cos(yaw))  # = wrap(-yaw)


def wrap_pi(angle: float) -> float:
    """``angle`` wrapped into (-pi, pi] (NaN stays NaN)."""
    return math.atan2(math.sin(angle), math.cos(angle))
