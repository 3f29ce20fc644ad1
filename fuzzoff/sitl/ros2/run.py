"""``fuzzoff sitl run PROGRAM --transport ros2``: one flight over PX4's ROS 2 bridge.

The flight runs in a private network namespace (``netns``) with this Python, which needs the
``ros2live`` extra (cyclonedds). Its outputs go to the save folder: the bag in mcap and sqlite3
storage, PX4's ULog, and what PX4 answered; each recording is then linted.
"""

from __future__ import annotations

import importlib.util
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzoff.sitl import bundle
from fuzzoff.sitl.ros2 import netns
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
) -> FlightOutcome:
    if program not in PROGRAMS:
        raise FlightError(f"no ROS 2 program {program!r}; have {', '.join(PROGRAMS)}")
    why = missing()
    if why is not None:
        raise FlightError(why)
    stem = f"{program}-{build.release}"
    log(f"{program} on PX4 {build.release} over its ROS 2 bridge (private network namespace)")
    bundled = build.folder.parent.resolve() == bundle.default_root().resolve()
    target = build.release if bundled else str(build.folder)
    done = netns.run_flight(save_dir.resolve(), [program, target, stem], timeout=FLIGHT_TIMEOUT_S)
    summary_file = save_dir / f"{stem}.json"
    if done.returncode != 0 or not summary_file.exists():
        tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
        raise FlightError(f"the flight failed: {' | '.join(tail)}")
    summary: dict[str, Any] = json.loads(summary_file.read_text())
    recordings = [save_dir / f"{stem}-{s}" for s in ("mcap", "sqlite3")]
    recordings += [p for p in [save_dir / f"{stem}.ulg"] if p.exists()]
    return FlightOutcome(program, build.release, save_dir, summary, recordings)


def render(outcome: FlightOutcome) -> str:
    s = outcome.summary
    lines = [f"PX4 {outcome.release}, {outcome.program} over the ROS 2 bridge: {outcome.folder}"]
    for t, note in s.get("notes", []):
        lines.append(f"  {t:8.3f} s  {note}")
    for ack in s.get("acks", []):
        lines.append(
            f"  {ack['t']:8.3f} s  ack of command {ack['command']}: result {ack['result']}"
        )
    for t, nav, arming, failsafe in s.get("modes", []):
        state = "armed" if arming == 2 else "disarmed"
        lines.append(f"  {t:8.3f} s  nav_state {nav}, {state}{', failsafe' if failsafe else ''}")
    lines += [f"  {p.name}" for p in outcome.recordings]
    return "\n".join(lines) + "\n"
