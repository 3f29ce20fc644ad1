"""``fuzzoff sitl run PROGRAM --transport ros2`` and ``fuzzoff sitl replay BAG --transport
ros2``: one flight over PX4's ROS 2 bridge.

The flight runs in a private network namespace (``netns``) with this Python, which needs the
``ros2live`` extra (cyclonedds). Its outputs go to the save folder: the bag in mcap and sqlite3
storage, PX4's ULog, and what PX4 answered; each recording is then linted.
"""

from __future__ import annotations

import importlib.util
import json
from collections.abc import Callable
from dataclasses import field
from pathlib import Path
from typing import Any

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl import airframes, bundle
from fuzzoff.sitl.ros2 import netns, replay
from fuzzoff.sitl.ros2.programs import PROGRAMS

FLIGHT_TIMEOUT_S = 240.0


class FlightError(Exception):
    """A flight that could not be flown: one line for the user."""


@dataclass(slots=True)
class FlightOutcome:
    program: str
    release: str
    folder: Path
    summary: dict[str, Any]
    recordings: list[Path] = field(default_factory=list)


def missing() -> str | None:
    """Why a flight cannot run here (None when it can)."""
    if importlib.util.find_spec("cyclonedds") is None:
        return "the ROS 2 transport needs cyclonedds: pip install 'fuzzoff[ros2live]'"
    return netns.available()


def fly(
    program: str,
    build: bundle.Build,
    save_dir: Path,
    log: Callable[[str], None] = print,
    vehicle: str | None = None,
) -> FlightOutcome:
    """``vehicle``: the SIH airframe (``fuzzoff.sitl.airframes``; None: the program's own)."""
    if program not in PROGRAMS:
        raise FlightError(f"no ROS 2 program {program!r}; have {', '.join(PROGRAMS)}")
    vehicle = vehicle or PROGRAMS[program].vehicle
    if vehicle is not None:
        try:
            airframes.boot_env(build, vehicle)
        except airframes.AirframeError as exc:
            raise FlightError(str(exc)) from None
    on = f", {vehicle}" if vehicle else ""
    log(f"{program} on PX4 {build.release}{on} over its ROS 2 bridge (private network namespace)")
    extra = ["--vehicle", vehicle] if vehicle else []
    return _flight(program, program, build, save_dir, extra=extra)


def replay_bag(
    path: Path,
    build: bundle.Build,
    save_dir: Path,
    log: Callable[[str], None] = print,
    params: dict[str, float] | None = None,
) -> FlightOutcome:
    """A recorded bag's ``/fmu/in`` messages sent to a fresh PX4 at their recorded times;
    ``params``: PX4 parameters set at its boot (``PX4_PARAM_<NAME>``, 1.16 and later)."""
    try:
        plan = replay.plan_from_bag(path, build.profile_release)
    except replay.ReplayError as exc:
        raise FlightError(str(exc)) from None
    save_dir.mkdir(parents=True, exist_ok=True)
    stem = f"{path.name}-on-{build.release}"
    plan_file = replay.save_plan(plan, save_dir.resolve() / f"{stem}.plan.json")
    log(f"{len(plan.messages)} messages of {path} to PX4 {build.release} over its ROS 2 bridge")
    extra = [f"--param={name}={value!r}" for name, value in sorted((params or {}).items())]
    return _flight(str(plan_file), "replay", build, save_dir, stem, extra)


def _flight(
    what: str,
    name: str,
    build: bundle.Build,
    save_dir: Path,
    stem: str | None = None,
    extra: list[str] | None = None,
) -> FlightOutcome:
    why = missing()
    if why is not None:
        raise FlightError(why)
    stem = stem or f"{name}-{build.release}"
    bundled = build.folder.parent.resolve() == bundle.default_root().resolve()
    target = build.release if bundled else str(build.folder)
    done = netns.run_flight(
        save_dir.resolve(), [what, target, stem, *(extra or [])], timeout=FLIGHT_TIMEOUT_S
    )
    summary_file = save_dir / f"{stem}.json"
    if done.returncode != 0 or not summary_file.exists():
        tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
        raise FlightError(f"the flight failed: {' | '.join(tail)}")
    summary: dict[str, Any] = json.loads(summary_file.read_text())
    recordings = [save_dir / f"{stem}-{s}" for s in ("mcap", "sqlite3")]
    recordings += [p for p in [save_dir / f"{stem}.ulg"] if p.exists()]
    return FlightOutcome(name, build.release, save_dir, summary, recordings)


def render(outcome: FlightOutcome) -> str:
    s = outcome.summary
    lines = [f"PX4 {outcome.release}, {outcome.program} over the ROS 2 bridge: {outcome.folder}"]
    rows: list[tuple[float, str]] = [(t, note) for t, note in s.get("notes", [])]
    rows += [(a["t"], f"ack of command {a['command']}: result {a['result']}") for a in s["acks"]]
    for t, nav, arming, failsafe in s.get("modes", []):
        state = "armed" if arming == 2 else "disarmed"
        rows.append((t, f"nav_state {nav}, {state}{', failsafe' if failsafe else ''}"))
    lines += [f"  {t:8.3f} s  {text}" for t, text in sorted(rows)]
    lines += [f"  {p.name}" for p in outcome.recordings]
    return "\n".join(lines) + "\n"
