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

# MAV_FRAME values MAVROS compares against (PositionTarget constants).
FRAME_LOCAL_NED = 1
FRAME_GLOBAL_INT = 5
FRAME_BODY_NED = 8
FRAME_BODY_OFFSET_NED = 9
BODY_FRAMES = frozenset({FRAME_BODY_NED, FRAME_BODY_OFFSET_NED})
"""Frames whose setpoint MAVROS turns from FLU to FRD, not from ENU to NED."""


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


def pose_rotation(q: Quat) -> Quat:
    """The rotation MAVROS takes from a ``geometry_msgs/Pose`` orientation (``setpoint_position``).

    MAVROS does not use the message's quaternion as it is: ``tf2::fromMsg`` (ROS 1:
    ``tf::poseMsgToEigen``) builds an ``Eigen::Affine3d`` from it, whose linear part is Eigen's
    ``toRotationMatrix()`` of the quaternion as given (no normalisation), and the plugin takes
    ``Eigen::Quaterniond(tr.rotation())``: the rotation factor of that matrix's polar
    decomposition (SVD, the last column's sign fixed so the determinant is +1, Eigen 3.4). So a
    unit quaternion is kept, the all-zero quaternion a program leaves unset (ROS 1's default)
    becomes the identity (yaw 0 in ENU, pi/2 in NED), and any other length gives the rotation
    nearest that matrix. The returned quaternion is a unit one (w >= 0 where it can be)."""
    w, x, y, z = q
    norm2 = w * w + x * x + y * y + z * z
    if not math.isfinite(norm2) or abs(norm2 - 1.0) <= 1e-12:
        return q  # a unit quaternion: toRotationMatrix() is a rotation, its own polar factor
    import numpy as np  # only for malformed orientations: not the hot path

    tx, ty, tz = 2.0 * x, 2.0 * y, 2.0 * z
    matrix = np.array(
        [
            [1.0 - (ty * y + tz * z), ty * x - tz * w, tz * x + ty * w],
            [ty * x + tz * w, 1.0 - (tx * x + tz * z), tz * y - tx * w],
            [tz * x - ty * w, tz * y + tx * w, 1.0 - (tx * x + ty * y)],
        ]
    )
    u, _, vt = np.linalg.svd(matrix)
    if np.linalg.det(u @ vt) < 0.0:
        u[:, 2] = -u[:, 2]
    return quat_from_matrix((u @ vt).tolist())


def quat_from_matrix(m: list[list[float]]) -> Quat:
    """A rotation matrix as a unit quaternion (w, x, y, z), as Eigen's ``Quaterniond(matrix)``
    (Shepperd's method: the largest of w, x, y, z is taken from the diagonal)."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        t = math.sqrt(trace + 1.0)
        w, k = 0.5 * t, 0.5 / t
        return (w, (m[2][1] - m[1][2]) * k, (m[0][2] - m[2][0]) * k, (m[1][0] - m[0][1]) * k)
    i = max(range(3), key=lambda n: m[n][n])
    j, k_ = (i + 1) % 3, (i + 2) % 3
    t = math.sqrt(m[i][i] - m[j][j] - m[k_][k_] + 1.0)
    v = [0.0, 0.0, 0.0]
    v[i] = 0.5 * t
    t = 0.5 / t
    w = (m[k_][j] - m[j][k_]) * t
    v[j] = (m[j][i] + m[i][j]) * t
    v[k_] = (m[k_][i] + m[i][k_]) * t
    return (w, v[0], v[1], v[2])


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
