"""``--from RECORDING``: perturb a user's real stream and find its margin.

Perturbations act on the sent keep-alive (and the setpoints published with it):

* ``stall``: nothing sent for ``size`` seconds from a keep-alive on (later messages shift);
* ``drop``: ``size`` consecutive keep-alive messages lost (as on a lossy link);
* ``jitter``: every sent message delayed by up to ``size`` seconds (deterministic pattern);
* ``skew``: the sender's timestamps off by ``-size`` seconds (an old clock).

The *margin* of a family is the smallest size that changes the gate model's outcome (the
hazards it predicts, ``fuzz.hazards``), found by bisection at each position, and where.
``mutations(scenario)`` is the Hypothesis strategy of perturbed scenarios the properties are
checked on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from hypothesis import strategies as st

from fuzzoff.events import Command, CommandAck, ControlMode, Event, is_keepalive
from fuzzoff.fuzz.hazards import hazards
from fuzzoff.fuzz.recordings import read_with_info
from fuzzoff.fuzz.scenario import Scenario, TransportName, run
from fuzzoff.fuzz.streams import settle
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import DEFAULT_PX4, DEFAULT_VEHICLE, ProfileError, px4_profile_for
from fuzzoff.releases import PX4Profile
from fuzzoff.timeline import Timeline

FAMILIES = ("stall", "drop", "jitter", "skew")
MAX_SIZE = {"stall": 5.0, "drop": 50.0, "jitter": 1.0, "skew": 5.0}
UNIT = {"stall": "s", "drop": "messages", "jitter": "s", "skew": "s"}


def scenario_from_recording(
    path: Path, px4: PX4Profile | None, vehicle: str | None, params: dict[str, float]
) -> Scenario:
    """The recording's events as a scenario (see ``read_base``)."""
    return read_base(path, px4, vehicle, params)[0]


def read_base(
    path: Path, px4: PX4Profile | None, vehicle: str | None, params: dict[str, float]
) -> tuple[Scenario, list[str]]:
    """The recording's events as a scenario (transport from its events; profile as given, else
    as the recording says, else PX4 1.15 multicopter like ``fuzzoff lint``), and the parts of
    the recording that could not be read (the scenario is what came before them), one line
    each. ``SourceError`` when the recording cannot be read at all."""
    events, info, problems = read_with_info(path)
    if px4 is None:
        try:
            px4 = px4_profile_for(info.px4_version) if info.px4_version else DEFAULT_PX4
        except ProfileError:
            px4 = DEFAULT_PX4
    vehicle = vehicle or info.vehicle_type or DEFAULT_VEHICLE
    transport: TransportName = "ros2"
    if any(getattr(e, "transport", "") == "mavros" for e in events):
        transport = "mavros"
    elif any(e.kind.startswith("set_") or getattr(e, "transport", "") == "mavlink" for e in events):
        transport = "mavlink"
    # In the generated streams' form (time-ordered from 0, strictly increasing at 0.1 ms, as
    # ``apply`` leaves every perturbed copy): a recording has events at one instant (a
    # HEARTBEAT gives a status and the vehicle's identity), and were only the copies settled,
    # a perturbation of size 0 would already move them, and so the outcome the margin measures.
    scenario = Scenario(
        px4=px4, vehicle=vehicle, transport=transport, events=tuple(settle(events)), params=params
    )
    return scenario, problems


def sent_keepalives(scenario: Scenario) -> int:
    """How many keep-alives the scenario sends: what the perturbations act on (a ULog has
    none, only the vehicle's own copies of the topics)."""
    return sum(1 for e in scenario.events if e.origin == "sent" and is_keepalive(e))


@dataclass(frozen=True, slots=True)
class Perturbation:
    family: str
    at: float
    """Time of the first keep-alive affected."""
    size: float

    def describe(self) -> str:
        size = f"{int(self.size)}" if self.family == "drop" else f"{self.size:.3f}"
        return f"{self.family} of {size} {UNIT[self.family]} at {self.at:.3f} s"


def apply(scenario: Scenario, p: Perturbation) -> Scenario:
    events = list(scenario.events)
    sent = [e for e in events if e.origin == "sent"]
    keep = [e for e in sent if is_keepalive(e)]
    if p.family == "stall":
        out = [e if e.t < p.at else _shift(e, p.size) for e in events]
    elif p.family == "drop":
        start = next((i for i, e in enumerate(keep) if e.t >= p.at), len(keep))
        gone = {id(e) for e in keep[start : start + int(p.size)]}
        out = [e for e in events if id(e) not in gone]
    elif p.family == "jitter":
        out = [
            _shift(e, p.size * (0.5 + 0.5 * math.sin(i * 2.39996)))
            if e.origin == "sent" and e.t >= p.at
            else e
            for i, e in enumerate(events)
        ]
        out = _acks_follow(events, out)
    else:  # skew
        out = [
            replace(e, sender_time_us=max(0, e.sender_time_us - round(p.size * 1e6)))
            if e.origin == "sent"
            and e.sender_time_us is not None
            and e.t >= p.at
            and isinstance(e, ControlMode)
            else e
            for e in events
        ]
    return replace(scenario, events=tuple(settle(out, from_zero=False)))


def _acks_follow(before: Sequence[Event], after: Sequence[Event]) -> list[Event]:
    """Each recorded ack moved at least as far as the command it answers (the latest one of
    that command before it): delaying a command past the vehicle's answer to it would leave an
    ack with nothing to answer. ``after`` is ``before`` perturbed, message for message."""
    moved: dict[int, float] = {}
    out = []
    for old, new in zip(before, after, strict=True):
        if isinstance(old, Command) and old.origin == "sent":
            moved[old.command] = new.t - old.t
        elif isinstance(old, CommandAck) and old.origin != "sent":
            delay = moved.get(old.command, 0.0)
            if new.t - old.t < delay:
                new = _shift(old, delay)
        out.append(new)
    return out


def _shift(e: Event, dt: float) -> Event:
    return replace(e, t=e.t + dt)


Outcome = tuple[tuple[str, int], ...]
"""Hazards as (kind, time in tenths of a second), sorted."""


def outcome(scenario: Scenario) -> Outcome:
    """The hazards the gate model predicts, by kind and rounded time (the outcome to change)."""
    timelines: dict[str, Timeline] = {}
    run(scenario, timelines=timelines)
    found = []
    for tl in timelines.values():
        found += [(h.kind, round(h.t * 10)) for h in hazards(tl.transitions, scenario.duration)]
    return tuple(sorted(found))


@dataclass(frozen=True, slots=True)
class Margin:
    family: str
    perturbation: Perturbation | None
    """The smallest perturbation that changes the outcome (None: none up to ``MAX_SIZE``)."""
    new_hazards: Outcome = ()
    changes: tuple[str, ...] = ()
    """What PX4 does differently after that perturbation (``fuzz.outcomes.changes``)."""

    def describe(self) -> str:
        p = self.perturbation
        if p is None:
            return "none up to the largest size tried"
        what = "; ".join(self.changes) or "changes the gate's outcome"
        return f"{p.describe()}: {what}"

    def to_json(self) -> dict[str, object]:
        p = self.perturbation
        return {
            "family": self.family,
            "found": p is not None,
            "size": None if p is None else p.size,
            "unit": UNIT[self.family],
            "at_s": None if p is None else round(p.at, 6),
            "max_tried": MAX_SIZE[self.family],
            "outcome_after": [{"hazard": k, "time_s": t / 10} for k, t in self.new_hazards],
            "changes": list(self.changes),
        }


def _positions(scenario: Scenario, count: int) -> list[float]:
    keep = [e.t for e in scenario.events if is_keepalive(e) and e.origin == "sent"]
    if len(keep) <= count:
        return keep
    step = len(keep) / count
    return [keep[int(i * step)] for i in range(count)]


def same_outcome(base: Outcome, got: Outcome, p: Perturbation) -> bool:
    """The same hazards, each within the time the perturbation itself moves the stream (a
    stall or jitter of 0.5 s delays a loss the stream already had by up to 0.5 s: the same
    outcome, later), plus the 0.1 s the outcome is rounded to."""
    if len(base) != len(got):
        return False
    moved = p.size if p.family in ("stall", "jitter") else 0.0
    slack = round(moved * 10) + 1
    pairs = zip(base, got, strict=True)
    return all(kind == other and abs(t - u) <= slack for (kind, t), (other, u) in pairs)


def margins(scenario: Scenario, positions: int = 24, steps: int = 12) -> list[Margin]:
    """Per family, the smallest perturbation (bisection per position) changing the outcome."""
    base = outcome(scenario)
    result = []
    for family in FAMILIES:
        best: Perturbation | None = None
        best_outcome: Outcome = ()
        for at in _positions(scenario, positions):
            hi = MAX_SIZE[family] if best is None else best.size
            widest = Perturbation(family, at, hi)
            changed = outcome(apply(scenario, widest))
            if same_outcome(base, changed, widest):
                continue
            lo, hi_outcome = 0.0, changed
            for _ in range(steps):
                mid = (lo + hi) / 2
                if family == "drop":
                    mid = float(math.floor(mid))
                    if mid <= lo:
                        break
                tried = Perturbation(family, at, mid)
                got = outcome(apply(scenario, tried))
                if not same_outcome(base, got, tried):
                    hi, hi_outcome = mid, got
                else:
                    lo = mid
            if best is None or hi < best.size:
                best, best_outcome = Perturbation(family, at, hi), hi_outcome
        result.append(Margin(family, best, best_outcome, _changes(scenario, best)))
    return result


def _changes(scenario: Scenario, p: Perturbation | None) -> tuple[str, ...]:
    if p is None:
        return ()
    from fuzzoff.fuzz.outcomes import changes, hazards_of

    moved = p.size if p.family in ("stall", "jitter") else 0.0
    before, after = hazards_of(scenario), hazards_of(apply(scenario, p))
    return tuple(changes(scenario.px4, before, after, moved))


def mutations(scenario: Scenario) -> st.SearchStrategy[Scenario]:
    """Perturbed copies of ``scenario`` (one or two perturbations)."""
    times = [e.t for e in scenario.events if is_keepalive(e)] or [0.0]
    one = st.builds(
        Perturbation,
        family=st.sampled_from(FAMILIES),
        at=st.sampled_from(times),
        size=st.floats(0.0, 3.0),
    )

    def perturb(ps: Sequence[Perturbation]) -> Scenario:
        out = scenario
        for p in ps:
            out = apply(out, p)
        return out

    return st.lists(one, min_size=1, max_size=2).map(perturb)
