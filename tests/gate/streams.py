"""Minimal event streams for the gate conformance tests (px4-offboard-gate.md)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from fuzzoff import releases
from fuzzoff.events import (
    Command,
    ControlMode,
    Event,
    FailsafeFlags,
    SetPositionTargetLocal,
    VehicleStatus,
)
from fuzzoff.gate import GateModel, GateTransition
from fuzzoff.profiles import Profile

ALL = list(releases.names())
TICK = [r.name for r in releases.RELEASES if r.tick_based]
"""Profiles with OffboardChecks at 10 Hz (gate spec 2.1)."""
OLD = ["legacy", "1.11", "1.13"]
RECEIVER_NEW = ["1.13", *TICK]
"""Profiles with the v1.12+ MAVLink receiver (gate spec 6.1)."""

OFFBOARD = 14
POSCTL, ALTCTL, STAB, RTL, LAND, LOITER, TERMINATION, MANUAL = 2, 1, 15, 5, 18, 4, 13, 0


def run(
    px4: str,
    events: Iterable[Event],
    *,
    params: dict[str, float] | None = None,
    vehicle: str = "mc",
    t_end: float | None = None,
    model: GateModel | None = None,
) -> list[GateTransition]:
    """Feed ``events`` (sorted by time) to a fresh model and return every transition."""
    gate = model or GateModel(Profile(px4=px4, vehicle=vehicle), params or {}, "1")
    out: list[GateTransition] = []
    ordered = sorted(events, key=lambda e: e.t)
    for event in ordered:
        out.extend(gate.feed(event))
    end = t_end if t_end is not None else (ordered[-1].t if ordered else 0.0)
    out.extend(gate.finish(end))
    return out


def model(px4: str, vehicle: str = "mc", **params: float) -> GateModel:
    return GateModel(Profile(px4=px4, vehicle=vehicle), params, "1")


def status(t: float, nav: int, armed: bool, intention: int | None = None) -> VehicleStatus:
    return VehicleStatus(t=t, nav_state=nav, armed=armed, user_intention=intention)


def in_offboard(t: float = 0.0) -> VehicleStatus:
    """A recording that starts armed in OFFBOARD."""
    return status(t, OFFBOARD, True, OFFBOARD)


def ocm(t: float, layout: str = "thrust_and_torque", **flags: Any) -> ControlMode:
    if not flags:
        flags = {"position": True}
    return ControlMode(t=t, layout=layout, **flags)  # type: ignore[arg-type]


def stream(t0: float, t1: float, period: float = 0.1, **flags: Any) -> list[ControlMode]:
    n = round((t1 - t0) / period)
    return [ocm(round(t0 + i * period, 6), **flags) for i in range(n + 1)]


def local_ned(t: float, mask: int = 0b110111111000, frame: int = 1, **kw: Any) -> Event:
    """SET_POSITION_TARGET_LOCAL_NED; the default mask uses position only."""
    return SetPositionTargetLocal(
        t=t, type_mask=mask, coordinate_frame=frame, target_system=1, target_component=1, **kw
    )


def switch_offboard(t: float) -> Command:
    return Command(t=t, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0))


def switch_mode(t: float, main: int, sub: int = 0) -> Command:
    return Command(t=t, command=176, params=(1.0, float(main), float(sub), 0.0, 0.0, 0.0, 0.0))


def arm(t: float) -> Command:
    return Command(t=t, command=400, params=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))


def flags(t: float, **kw: bool) -> FailsafeFlags:
    return FailsafeFlags(t=t, **kw)  # type: ignore[arg-type]


def of(kind: str, trs: Sequence[GateTransition]) -> list[GateTransition]:
    return [tr for tr in trs if tr.what == kind]


def loss_times(trs: Sequence[GateTransition]) -> list[float]:
    return [tr.t for tr in of("signal_lost", trs)]


def failsafe_actions(trs: Sequence[GateTransition]) -> list[str | None]:
    return [tr.action for tr in of("failsafe", trs)]
