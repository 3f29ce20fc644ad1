"""Tiny builders for event streams used by the rule tests (the engine without a file)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from fuzzoff.config import Settings
from fuzzoff.engine import run_events
from fuzzoff.events import Command, CommandAck, ControlMode, Event, VehicleStatus
from fuzzoff.findings import Finding
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo

OFFBOARD = 14
POSCTL = 2


def ocm(times: Iterable[float], **flags: bool) -> list[Event]:
    flags = flags or {"position": True}
    return [ControlMode(t=round(t, 6), **flags) for t in times]


def every(start: float, stop: float, step: float) -> list[float]:
    n = round((stop - start) / step)
    return [start + i * step for i in range(n + 1)]


def status(t: float, nav_state: int, armed: bool = True) -> VehicleStatus:
    return VehicleStatus(t=t, nav_state=nav_state, armed=armed)


def switch(t: float) -> Command:
    return Command(t=t, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0))


def ack(t: float, result: int, command: int = 176) -> CommandAck:
    return CommandAck(t=t, command=command, result=result)


def lint_events(
    events: Sequence[Event],
    *,
    px4: str = "1.15",
    vehicle: str = "mc",
    fmt: str = "mcap",
    sampled: dict[str, float] | None = None,
    settings: Settings | None = None,
) -> list[Finding]:
    ordered = sorted(events, key=lambda e: e.t)
    info = RecordingInfo("stream", fmt, kinds={e.kind for e in ordered})
    if sampled:
        info.sampled_intervals = sampled
    profile = Profile(px4=px4, vehicle=vehicle, px4_detected=True, vehicle_detected=True)
    findings, _ = run_events(ordered, info, profile, settings or Settings())
    return findings


def codes(findings: Iterable[Finding], code: str) -> list[Finding]:
    return [f for f in findings if f.code == code]
