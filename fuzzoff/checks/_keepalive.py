"""What the stream rules share: which events are keep-alive, what a gap proves, PX4's timeout."""

from __future__ import annotations

from fuzzoff.checks.base import CheckContext
from fuzzoff.events import (
    KEEPALIVE_TYPES,
    ControlMode,
    Dropout,
    Event,
    LegacyControlMode,
    MavlinkTarget,
)

KEEPALIVE_EVENTS: tuple[type[Event], ...] = (*KEEPALIVE_TYPES, Dropout)
"""What a stream rule subscribes to: the keep-alive kinds, and logger dropouts (ULog)."""


def counts_as_keepalive(ctx: CheckContext, event: Event) -> bool:
    """The docs' keep-alive: an OCM, or a supported MAVLink setpoint addressed to this vehicle."""
    if isinstance(event, MavlinkTarget):
        own = int(ctx.vehicle) if ctx.vehicle.isdigit() else None
        return event.target_system == 0 or own is None or event.target_system == own
    return isinstance(event, (ControlMode, LegacyControlMode))


def logging_interval(ctx: CheckContext, event: Event) -> float:
    """The logger's interval for this kind in a subsampled recording (ULog), else 0."""
    return ctx.info.sampled_intervals.get(event.kind, 0.0)


TIME_EPSILON_S = 1e-6
"""Recording clocks are integers (µs, ns); differences of their float seconds are not exact."""


def proven_gap(ctx: CheckContext, event: Event, gap: float) -> float:
    """The gap the recording proves: in a subsampled log a logged gap may hide one interval."""
    return max(0.0, gap - logging_interval(ctx, event)) + TIME_EPSILON_S


def loss_timeout(ctx: CheckContext) -> float:
    """The gap after which the profile's PX4 declares the offboard signal lost (gate spec 2)."""
    if ctx.profile.px4 == "legacy":
        return 0.5
    value = ctx.gate.params.get("COM_OF_LOSS_T")
    default = 0.5 if ctx.profile.px4 == "1.11" else 1.0
    return float(default if value is None else value)


def px4_label(ctx: CheckContext) -> str:
    """``PX4 1.15`` (or ``PX4 legacy``) for "docs: …; PX4 1.15 would: …" messages."""
    return f"PX4 {ctx.profile.px4}"


def offboard_and_flying(ctx: CheckContext) -> bool:
    """In offboard and not known to be disarmed (a disarmed vehicle parked in OFFBOARD is idle)."""
    return ctx.state.in_offboard and ctx.state.armed is not False


def mode_note(ctx: CheckContext) -> str:
    return "" if ctx.state.mode_recorded else " (mode predicted by the gate model)"
