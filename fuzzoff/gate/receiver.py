"""PX4's MAVLink receiver: which setpoint messages it accepts, and the keep-alive they produce
(gate.md#receiver).

``receive(msg, ctx)`` returns ``(ocm_mask, axes, reason, spec)``: ``ocm_mask`` is the
``offboard_control_mode`` flag mask the receiver publishes (``DROPPED`` when the message is
dropped and so gives no keep-alive), ``axes`` the per-axis finiteness of the trajectory setpoint
it would publish (``controllers.axes_*`` bits), ``reason`` why it was dropped (or a warning),
``spec`` the section.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from fuzzoff.events import (
    MavlinkTarget,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
)
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.ocm import ACCELERATION, ATTITUDE, BODY_RATE, POSITION, VELOCITY
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.releases import Release
from fuzzoff.type_mask import (
    ACCELERATION_BITS,
    FORCE_SET,
    POSITION_BITS,
    SETPOINT_IDLE,
    SETPOINT_LAND,
    SETPOINT_LOITER,
    SETPOINT_TAKEOFF,
    VECTOR_BITS,
    VELOCITY_BITS,
    YAW_IGNORE,
    YAW_RATE_IGNORE,
)

DROPPED = -1
_LEGACY_KINDS = {SETPOINT_TAKEOFF: "takeoff", SETPOINT_LAND: "land", SETPOINT_LOITER: "loiter"}


Result = tuple[int, int, "str | None", str]


@dataclass(slots=True)
class ReceiverContext:
    """What the receiver reads besides the message (6.1)."""

    release: Release
    own_system: int | None
    own_component: int
    fwdextsp: bool
    est: Estimates
    old_rule: bool = False
    """v1.13's "any component finite" flag rule instead of 1.14's "not all NaN" (6.2)."""
    legacy: bool = False
    """The legacy / 1.11 receiver (6.4 legacy, 6.5)."""

    def __post_init__(self) -> None:
        self.old_rule = self.release.setpoint_valid_if_any_finite
        self.legacy = self.release.legacy_receiver


def _target_ok(msg: MavlinkTarget, ctx: ReceiverContext) -> str | None:
    if ctx.own_system is not None and msg.target_system not in (0, ctx.own_system):
        return f"target_system {msg.target_system} is not this vehicle ({ctx.own_system})"
    if msg.target_component not in (0, ctx.own_component):
        return f"target_component {msg.target_component} is not the autopilot ({ctx.own_component})"
    return None


def _finite3(v: tuple[float, float, float]) -> int:
    isf = math.isfinite
    return (1 if isf(v[0]) else 0) | (2 if isf(v[1]) else 0) | (4 if isf(v[2]) else 0)


def _present3(v: tuple[float, float, float], ignore: int, old_rule: bool) -> tuple[int, bool]:
    """(finite-axis bits, flag) for one vector with its 3 ignore bits (bit i = ignore axis i).

    v1.14+: the flag is "not all NaN" (Inf counts as present); v1.13: "any component finite"
    (6.2)."""
    finite = 0
    present = False
    for i in range(3):
        if ignore & (1 << i):
            continue
        value = v[i]
        if math.isfinite(value):
            finite |= 1 << i
            present = True
        elif not old_rule and not math.isnan(value):
            present = True
    return finite, present


Shape = tuple[object, ...]
"""Everything ``receive`` reads from one message, as a cache key (see ``shape``)."""

FLOAT_FIELDS: dict[type, tuple[tuple[str, ...], tuple[str, ...]]] = {
    SetPositionTargetLocal: (("position", "velocity", "acceleration"), ("yaw", "yaw_rate")),
    SetPositionTargetGlobal: (("velocity", "acceleration"), ("alt", "yaw", "yaw_rate")),
    SetAttitudeTarget: (("q",), ("thrust", "body_roll_rate", "body_pitch_rate", "body_yaw_rate")),
}
"""The float fields of each message ``receive`` classifies (vectors, then single values): the
ones whose finiteness the shape must settle. The ``_*_shape`` functions below are this table
unrolled (they run once per message); ``tests/gate/test_fast_paths.py`` ties the two."""


def _local_shape(msg: SetPositionTargetLocal) -> Shape | None:
    px, py, pz = msg.position
    vx, vy, vz = msg.velocity
    ax, ay, az = msg.acceleration
    # A sum of floats is finite only if every term is (an overflow only sends the message to
    # the uncached path), so one test proves that every float receive() classifies is finite.
    if not math.isfinite(px + py + pz + vx + vy + vz + ax + ay + az + msg.yaw + msg.yaw_rate):
        return None
    return (
        SetPositionTargetLocal,
        msg.type_mask,
        msg.coordinate_frame,
        msg.target_system,
        msg.target_component,
    )


def _global_shape(msg: SetPositionTargetGlobal) -> Shape | None:
    vx, vy, vz = msg.velocity
    ax, ay, az = msg.acceleration
    if not math.isfinite(vx + vy + vz + ax + ay + az + msg.alt + msg.yaw + msg.yaw_rate):
        return None
    return (
        SetPositionTargetGlobal,
        msg.type_mask,
        msg.coordinate_frame,
        msg.target_system,
        msg.target_component,
    )


def _attitude_shape(msg: SetAttitudeTarget) -> Shape | None:
    qw, qx, qy, qz = msg.q
    rates = msg.body_roll_rate + msg.body_pitch_rate + msg.body_yaw_rate
    if not math.isfinite(qw + qx + qy + qz + msg.thrust + rates):
        return None
    return (SetAttitudeTarget, msg.type_mask, msg.target_system, msg.target_component)


SHAPES: dict[type, Callable[[Any], Shape | None]] = {
    SetPositionTargetLocal: _local_shape,
    SetPositionTargetGlobal: _global_shape,
    SetAttitudeTarget: _attitude_shape,
}


def shape(msg: MavlinkTarget) -> Shape | None:
    """A cache key for ``receive(msg, ctx)`` under a fixed ``ctx``, or None (do not cache).

    ``receive`` reads from the message its type, ``type_mask``, ``coordinate_frame``, the
    target ids and, of its float fields, only whether each is finite (NaN or Inf). The key holds
    the former; the latter is settled by answering None unless every float field is finite.
    Two messages with the same key thus get the same answer from the same context."""
    of = SHAPES.get(type(msg))
    return None if of is None else of(msg)


def receive(msg: MavlinkTarget, ctx: ReceiverContext) -> Result:
    if ctx.legacy:
        return _legacy(msg, ctx)
    if not ctx.fwdextsp:
        return DROPPED, 0, "MAV_FWDEXTSP is 0: setpoint handling is off", "6.1"
    bad = _target_ok(msg, ctx)
    if bad is not None:
        return DROPPED, 0, bad, "6.1"
    if isinstance(msg, SetAttitudeTarget):
        return _attitude(msg, ctx)
    return _position(msg, ctx)


def _position(msg: MavlinkTarget, ctx: ReceiverContext) -> Result:
    mask = msg.type_mask
    old_rule = ctx.old_rule
    frame: int = getattr(msg, "coordinate_frame", 1)
    velocity: tuple[float, float, float] = getattr(msg, "velocity", (0.0, 0.0, 0.0))
    acceleration: tuple[float, float, float] = getattr(msg, "acceleration", (0.0, 0.0, 0.0))
    pos_f = vel_f = acc_f = 0
    pos_p = vel_p = acc_p = False
    if isinstance(msg, SetPositionTargetGlobal):
        spec = "6.3"
        if not mask & POSITION_BITS:
            if frame not in (5, 6, 11):
                return DROPPED, 0, f"invalid coordinate frame {frame}", spec
            if not ctx.est.global_position:
                return DROPPED, 0, "no global position reference (dropped silently)", spec
            if frame == 6 and not ctx.est.home_position:
                return DROPPED, 0, "no home altitude for GLOBAL_RELATIVE_ALT_INT", spec
            pos_f = 0b111 if math.isfinite(msg.alt) else 0b011
            pos_p = True
        vel_f, vel_p = _present3(velocity, (mask & VELOCITY_BITS) >> 3, old_rule)
        acc_f, acc_p = _present3(acceleration, (mask & ACCELERATION_BITS) >> 6, old_rule)
    else:
        spec = "6.2"
        position: tuple[float, float, float] = getattr(msg, "position", (0.0, 0.0, 0.0))
        if frame == 1:
            used = ~mask & VECTOR_BITS
            isf = math.isfinite
            finite = (
                isf(position[0])
                | isf(position[1]) << 1
                | isf(position[2]) << 2
                | isf(velocity[0]) << 3
                | isf(velocity[1]) << 4
                | isf(velocity[2]) << 5
                | isf(acceleration[0]) << 6
                | isf(acceleration[1]) << 7
                | isf(acceleration[2]) << 8
            )
            if used & ~finite:  # a used field is NaN or Inf: the exact per-version rule
                pos_f, pos_p = _present3(position, mask & POSITION_BITS, old_rule)
                vel_f, vel_p = _present3(velocity, (mask & VELOCITY_BITS) >> 3, old_rule)
                acc_f, acc_p = _present3(acceleration, (mask & ACCELERATION_BITS) >> 6, old_rule)
            else:
                axes = used & finite
                pos_f, vel_f, acc_f = axes & 7, (axes >> 3) & 7, axes >> 6
                pos_p, vel_p, acc_p = pos_f != 0, vel_f != 0, acc_f != 0
        elif frame == 8:
            # BODY_NED: position always ignored; any ignore bit drops the whole vector.
            if not mask & VELOCITY_BITS:
                vel_f, vel_p = _present3(velocity, 0, old_rule)
                if vel_f & 3 != 3:
                    vel_f &= 4  # rotated by yaw: a NaN in x or y spoils both
            if not mask & ACCELERATION_BITS:
                acc_f, acc_p = _present3(acceleration, 0, old_rule)
                if acc_f != 7:
                    acc_f = 0  # rotated by the full attitude
        else:
            return DROPPED, 0, f"coordinate frame {frame} unsupported", spec
    if acc_p and mask & FORCE_SET:
        return DROPPED, 0, "force setpoint not supported (FORCE_SET bit)", spec
    if not (pos_p or vel_p or acc_p):
        what = "no position, velocity or acceleration"
        if not mask & YAW_IGNORE or not mask & YAW_RATE_IGNORE:
            what += " (yaw-only message)"
        return DROPPED, 0, what, spec
    ocm = (POSITION if pos_p else 0) | (VELOCITY if vel_p else 0) | (ACCELERATION if acc_p else 0)
    if ctx.release.yaw_sets_attitude_flags:
        yaw: float = getattr(msg, "yaw", math.nan)
        yaw_rate: float = getattr(msg, "yaw_rate", math.nan)
        if not mask & YAW_IGNORE and math.isfinite(yaw):
            ocm |= ATTITUDE
        if not mask & YAW_RATE_IGNORE and math.isfinite(yaw_rate):
            ocm |= BODY_RATE
    return ocm, pos_f | (vel_f << 3) | (acc_f << 6), None, spec


def _attitude(msg: SetAttitudeTarget, ctx: ReceiverContext) -> Result:
    mask = msg.type_mask
    attitude = not mask & 128
    rates = not mask & 1 and not mask & 2
    if ctx.release.attitude_target_needs_thrust and not (not mask & 64 or mask & 32):
        return DROPPED, 0, "no thrust (main requires thrust in SET_ATTITUDE_TARGET)", "6.4"
    if not (attitude or rates):
        return DROPPED, 0, "attitude and body rates both ignored", "6.4"
    return (ATTITUDE if attitude else 0) | (BODY_RATE if rates else 0), 0, None, "6.4"


def _all_finite(*values: float) -> bool:
    return all(math.isfinite(v) for v in values)


def _legacy(msg: MavlinkTarget, ctx: ReceiverContext) -> Result:
    """legacy / 1.11 receiver (6.4 legacy, 6.5): no MAV_FWDEXTSP gate on the keep-alive."""
    bad = _target_ok(msg, ctx)
    if bad is not None:
        return DROPPED, 0, bad, "6.5"
    mask = msg.type_mask
    if isinstance(msg, SetAttitudeTarget):
        q = msg.q
        if not _all_finite(
            *q, msg.thrust, msg.body_roll_rate, msg.body_pitch_rate, msg.body_yaw_rate
        ):
            return DROPPED, 0, "a non-finite field (legacy drops the whole message)", "6.4"
        ocm = (0 if mask & 7 else BODY_RATE) | (0 if mask & 128 else ATTITUDE)
        return ocm, 0, None, "6.4"
    if isinstance(msg, SetPositionTargetGlobal):
        if not ctx.release.handles_global_int:
            return DROPPED, 0, "SET_POSITION_TARGET_GLOBAL_INT not handled (legacy)", "6.3"
        return VELOCITY, 0, "legacy-style GLOBAL_INT handler (unverified)", "6.3"
    position: tuple[float, float, float] = getattr(msg, "position", (0.0, 0.0, 0.0))
    velocity: tuple[float, float, float] = getattr(msg, "velocity", (0.0, 0.0, 0.0))
    acceleration: tuple[float, float, float] = getattr(msg, "acceleration", (0.0, 0.0, 0.0))
    yaw: float = getattr(msg, "yaw", 0.0)
    if not _all_finite(*position, *velocity, *acceleration, yaw):
        return DROPPED, 0, "a non-finite field (legacy drops the whole message)", "6.5"
    ocm = (
        (0 if mask & POSITION_BITS else POSITION)
        | (0 if mask & VELOCITY_BITS else VELOCITY)
        | (0 if mask & ACCELERATION_BITS else ACCELERATION)
        | (0 if mask & YAW_IGNORE else ATTITUDE)
        | (0 if mask & YAW_RATE_IGNORE else BODY_RATE)
    )
    axes = (0 if mask & POSITION_BITS else 7) | (0 if mask & VELOCITY_BITS else 56)
    axes |= 0 if mask & ACCELERATION_BITS else 448
    reason = None
    if mask & FORCE_SET and mask & POSITION_BITS and mask & VELOCITY_BITS:
        reason = "force setpoint not supported (keep-alive still sent, setpoint not forwarded)"
    elif mask & SETPOINT_LOITER and mask & SETPOINT_IDLE == 0:
        value = mask & SETPOINT_LOITER
        kind = _LEGACY_KINDS[value]
        if kind != "loiter":
            # v1.6.4-v1.11; v1.5-v1.6.3 tested takeoff first (docs/gate.md, the receiver row)
            reason = f"setpoint type {kind} ({value}) is classified as LOITER in legacy"
    return ocm, axes, reason, "6.5"
