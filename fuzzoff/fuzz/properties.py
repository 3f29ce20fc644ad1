"""The claims a campaign checks on every example; each returns the problems it found ([] = holds).

* ``every_unintended_outcome_is_explained`` (a): every hazard the gate model predicts
  (``fuzz.hazards``) is explained by an error finding of a rule that covers it, at or before
  the hazard (+ ``TOLERANCE_S``; for a controller hazard, before it ends: a rule may need a
  moment to be sure no setpoint is coming). Where the rule reporting the outcome itself cannot
  be checked on the recording (OFB002 names it, or OFB201 without any ack), a warning of a
  covering rule is enough.
* ``docs_stricter_rules_are_counted`` (b): never fails; counts per rule the findings of rules
  that have a docs-vs-code note while the gate model saw no hazard in the finding's window:
  "docs stricter than code".
* ``recordings_round_trip`` (c): written with the real writers and read back, the stream gives
  the same events (every field but ``where``; times within 1 us) and ``fuzzoff lint`` gives the
  same findings (code, severity, vehicle, time within 1 ms) as the stream itself.
* ``truncated_recordings_give_a_prefix`` (d): cut at any byte, a recording lints without an
  exception, and its findings are a prefix of the whole file's. *Prefix*: every finding of the
  cut file that is before ``cut_t - EDGE_S`` (``cut_t`` = time of the last event the cut file
  still gives) is also a finding of the whole file; findings without a time, OFB001 (the cut
  itself), OFB002, OFB003 and OFB004 are left out: they describe the file, not the stream. So is a
  finding about a stretch that runs into that edge (its ``end_s``): the cut closed the stretch,
  and its verdict (OFB105's percentiles, say) is on the part the cut left.
* ``gate_invariants_hold`` (e): invariants of the gate model, on the sent stream (see
  ``fuzz.invariants``).
* ``runs_match_single_messages`` (f): the checks that take the stream as runs
  (``on_batch``) report exactly what they report when given one message at a time.
"""

from __future__ import annotations

import itertools
import math
import shutil
import tempfile
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import field, fields
from pathlib import Path
from typing import Any

from fuzzoff.catalog import get_rule
from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.events import NAV_STATE_OFFBOARD, Event, VehicleStatus
from fuzzoff.findings import Finding, Severity
from fuzzoff.formats import SourceError
from fuzzoff.fuzz import recordings
from fuzzoff.fuzz.hazards import EXPLAINED_BY, OUTCOME_RULE, Hazard, hazards
from fuzzoff.fuzz.invariants import invariant_violations
from fuzzoff.fuzz.scenario import Scenario, run
from fuzzoff.gate.params import default_params, loss_timeout
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.timeline import Timeline

TOLERANCE_S = 0.15
"""An explaining finding may come this much after the hazard (the gate's 10 Hz evaluation)."""
EDGE_S = 2.5
"""Findings this close to a cut are left out of the prefix comparison: rules judge windows
(a gap, a stretch, the answer to a request) that the cut ends early."""
FILE_LEVEL = frozenset({"OFB001", "OFB002", "OFB003", "OFB004"})


@dataclass(slots=True)
class FuzzContext:
    """What the properties share during a campaign."""

    settings: Settings = field(default_factory=Settings)
    workdir: Path = field(default_factory=lambda: Path(tempfile.mkdtemp(prefix="fuzzoff-")))
    docs_fired: Counter[str] = field(default_factory=Counter)
    docs_stricter: Counter[str] = field(default_factory=Counter)
    reached: Counter[str] = field(default_factory=Counter)
    """Rule code -> the examples it gave a finding on (any severity; the properties that lint
    the stream count it): which rules a campaign's streams reach."""
    cut_fraction: float = 1.0
    """Where ``truncated_recordings_give_a_prefix`` cuts (drawn per example)."""
    first_only: bool = True
    """``every_unintended_outcome_is_explained`` reports the first silent hazard only."""
    recorded_answers: bool = False
    """The vehicle's side is a recording's (``--from``, a reproducer): it answered the stream
    before it was perturbed, so it may contradict the model (see ``contradicted``)."""

    def close(self) -> None:
        shutil.rmtree(self.workdir, ignore_errors=True)


Property = Callable[[Scenario, FuzzContext], list[str]]


def _timelines(scenario: Scenario, ctx: FuzzContext) -> tuple[list[Finding], dict[str, Timeline]]:
    timelines: dict[str, Timeline] = {}
    findings = run(scenario, ctx.settings, timelines=timelines)
    ctx.reached.update({f.code for f in findings})
    return findings, timelines


def _not_checkable(findings: Sequence[Finding], scenario: Scenario) -> set[str]:
    """Rules the recording cannot feed: named by OFB002, and OFB201 without any ack."""
    blind = {f.message.split(" ", 1)[0] for f in findings if f.code == "OFB002"}
    if not any(e.kind == "command_ack" for e in scenario.events):
        blind.add("OFB201")
    return blind


def explains(hazard: Hazard, findings: Sequence[Finding], blind: set[str]) -> bool:
    """Is ``hazard`` explained by one of ``findings``? (see the module docstring)"""
    codes = EXPLAINED_BY[hazard.kind]
    outcome = OUTCOME_RULE.get(hazard.kind)
    lowest = Severity.WARNING if outcome is not None and outcome in blind else Severity.ERROR
    for f in findings:
        if f.code not in codes or f.severity < lowest:
            continue
        if f.time_s is None or f.time_s <= hazard.end + TOLERANCE_S:
            return True
    return False


RECORDED_ANSWER_S = 1.0
"""How soon after a rejection the recording's own status may show it granted (a 1 Hz
HEARTBEAT or ``/mavros/state``)."""


def contradicted(hazard: Hazard, findings: Sequence[Finding], statuses: Sequence[Event]) -> bool:
    """Does the recording's own vehicle side contradict the model during ``hazard``? Then the
    hazard belongs to a stream the vehicle never answered: a perturbed copy keeps the answers
    to the original one. Contradicted: the recorded mode is not the model's (OFB202) within
    the hazard, or a rejected switch or arming shows granted in the recorded status soon
    after."""
    if any(
        f.code == "OFB202"
        and f.time_s is not None
        and hazard.t - TOLERANCE_S <= f.time_s <= hazard.end + TOLERANCE_S
        for f in findings
    ):
        return True
    if hazard.kind not in ("arm_rejected", "request_rejected"):
        return False
    arming = hazard.kind == "arm_rejected"
    return any(
        isinstance(s, VehicleStatus)
        and hazard.t - TOLERANCE_S <= s.t <= hazard.end + RECORDED_ANSWER_S
        and (s.armed is True if arming else s.nav_state == NAV_STATE_OFFBOARD)
        for s in statuses
    )


def every_unintended_outcome_is_explained(scenario: Scenario, ctx: FuzzContext) -> list[str]:
    """Only the first silent hazard of a vehicle is reported (later ones are counted): they are
    often its consequences (a dropped keep-alive, then a rejected switch)."""
    findings, timelines = _timelines(scenario, ctx)
    blind = _not_checkable(findings, scenario)
    statuses: dict[str, list[Event]] = {vehicle: [] for vehicle in timelines}
    for e in scenario.events:
        if isinstance(e, VehicleStatus) and e.origin != "sent" and e.vehicle in statuses:
            statuses[e.vehicle].append(e)
    problems = []
    for vehicle, timeline in sorted(timelines.items()):
        mine = [f for f in findings if f.vehicle == vehicle or f.time_s is None]
        silent = [
            h
            for h in hazards(timeline.transitions, scenario.duration)
            if not explains(h, mine, blind)
            and not (ctx.recorded_answers and contradicted(h, mine, statuses[vehicle]))
        ]
        head = f"silent hazard ({scenario.transport}, PX4 {scenario.px4})"
        if silent and ctx.first_only:
            more = f" ({len(silent) - 1} later ones too)" if len(silent) > 1 else ""
            problems.append(f"{head}: {silent[0].describe()}, no finding explains it{more}")
        elif silent:
            problems += [f"{head}: {h.describe()}, no finding explains it" for h in silent]
    return problems


def docs_stricter_rules_are_counted(scenario: Scenario, ctx: FuzzContext) -> list[str]:
    findings, timelines = _timelines(scenario, ctx)
    found = [h for tl in timelines.values() for h in hazards(tl.transitions, scenario.duration)]
    timeout = loss_timeout(scenario.px4, default_params(scenario.px4) | dict(scenario.params))
    for f in findings:
        if f.time_s is None or f.code in FILE_LEVEL or f.severity < Severity.WARNING:
            continue
        if not get_rule(f.code).docs_vs_code:
            continue
        ctx.docs_fired[f.code] += 1
        start = f.time_s - TOLERANCE_S
        end = (f.end_s if f.end_s is not None else f.time_s) + timeout + TOLERANCE_S
        if not any(start <= h.t <= end for h in found):
            ctx.docs_stricter[f.code] += 1
    return []


# ----------------------------------------------------------------------------- round trip


def _same_value(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return abs(a - b) <= 1e-6 * max(1.0, abs(a))
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same_value(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


def event_differences(want: Sequence[Event], got: Sequence[Event], limit: int = 3) -> list[str]:
    """How ``got`` differs from ``want`` (field by field, ``where`` ignored)."""
    problems: list[str] = []
    if len(want) != len(got):
        kinds_w = Counter(e.kind for e in want)
        kinds_g = Counter(e.kind for e in got)
        problems.append(
            f"{len(want)} events written, {len(got)} read back "
            f"(missing {dict(kinds_w - kinds_g)}, extra {dict(kinds_g - kinds_w)})"
        )
    for i, (a, b) in enumerate(zip(want, got, strict=False)):
        if type(a) is not type(b):
            problems.append(f"event {i}: {a.kind} written, {b.kind} read back")
        elif abs(a.t - b.t) > 1e-6:
            problems.append(f"event {i} ({a.kind}): t {a.t!r} written, {b.t!r} read back")
        else:
            for f in fields(a):
                if f.name in ("where", "t"):
                    continue
                va, vb = getattr(a, f.name), getattr(b, f.name)
                if not _same_value(va, vb):
                    problems.append(
                        f"event {i} ({a.kind} at {a.t:.4f} s): {f.name} {va!r} written, "
                        f"{vb!r} read back"
                    )
        if len(problems) >= limit:
            break
    return problems


FindingKey = tuple[str, str, str, float | None]


def _keys(findings: Sequence[Finding]) -> list[FindingKey]:
    return [
        (f.code, f.severity.label, f.vehicle, None if f.time_s is None else round(f.time_s, 3))
        for f in findings
    ]


def finding_differences(want: Sequence[Finding], got: Sequence[Finding]) -> list[str]:
    a, b = Counter(_keys(want)), Counter(_keys(got))
    out = [f"missing {k[0]} {k[1]} at {k[3]}" for k in sorted(a - b, key=str)]
    out += [f"extra {k[0]} {k[1]} at {k[3]}" for k in sorted(b - a, key=str)]
    return out


def recordings_round_trip(scenario: Scenario, ctx: FuzzContext) -> list[str]:
    problems: list[str] = []
    direct = run(scenario, ctx.settings)
    for fmt in recordings.FORMATS_FOR[scenario.transport]:
        path = ctx.workdir / f"roundtrip{recordings.SUFFIX[fmt]}"
        _remove(path)
        recordings.write(scenario, path, fmt)
        try:
            back = recordings.read(path)
        except SourceError as exc:
            problems.append(f"{fmt}: written recording unreadable: {exc.line()}")
            continue
        problems += [f"{fmt}: {p}" for p in event_differences(scenario.events, back)]
        report = lint_file(path, scenario.settings(ctx.settings))
        if report.problems:
            problems.append(f"{fmt}: reader problems: {report.problems[0]}")
        diff = finding_differences(direct, report.findings)
        problems += [f"{fmt}: lint of the recording vs the stream: {d}" for d in diff[:4]]
        _remove(path)
    return problems


def _remove(path: Path) -> None:
    if path.is_dir():
        shutil.rmtree(path)
    elif path.exists():
        path.unlink()


# ----------------------------------------------------------------------------- truncation


def truncated_recordings_give_a_prefix(scenario: Scenario, ctx: FuzzContext) -> list[str]:
    fmt = recordings.FORMATS_FOR[scenario.transport][0]
    path = ctx.workdir / f"whole{recordings.SUFFIX[fmt]}"
    cut_path = ctx.workdir / f"cut{recordings.SUFFIX[fmt]}"
    _remove(path)
    recordings.write(scenario, path, fmt)
    data = path.read_bytes()
    cut = min(len(data), max(0, round(ctx.cut_fraction * len(data))))
    cut_path.write_bytes(data[:cut])
    settings = scenario.settings(ctx.settings)
    whole = lint_file(path, settings)
    try:
        part = lint_file(cut_path, settings)
    except Exception as exc:  # the claim is exactly that nothing escapes
        return [f"{fmt} cut at byte {cut} of {len(data)}: {type(exc).__name__}: {exc}"]
    try:
        events = recordings.read(cut_path)
    except SourceError:
        events = []
    except Exception as exc:
        return [f"{fmt} cut at byte {cut} of {len(data)}: reader raised {type(exc).__name__}"]
    cut_t = events[-1].t if events else 0.0
    problems = []
    remaining = Counter(_keys(whole.findings))
    for f in part.findings:
        if f.code in FILE_LEVEL or f.time_s is None or f.time_s > cut_t - EDGE_S:
            continue
        if f.end_s is not None and f.end_s > cut_t - EDGE_S:
            continue  # a stretch the cut closed: judged on the part the cut left
        (key,) = _keys([f])
        if remaining[key] > 0:
            remaining[key] -= 1
            continue
        near = [
            k
            for k in remaining
            if k[:3] == key[:3]
            and k[3] is not None
            and key[3] is not None
            and abs(k[3] - key[3]) <= 0.05
            and remaining[k] > 0
        ]
        if near:
            remaining[near[0]] -= 1
            continue
        problems.append(
            f"{fmt} cut at byte {cut} of {len(data)} (last event {cut_t:.3f} s): {f.code} at "
            f"{f.time_s:.3f} s is not a finding of the whole file: {f.message}"
        )
    return problems[:3]


# ----------------------------------------------------------------------------- invariants


def gate_invariants_hold(scenario: Scenario, ctx: FuzzContext) -> list[str]:
    return invariant_violations(scenario)


# ----------------------------------------------------------------------------- runs


def runs_match_single_messages(scenario: Scenario, ctx: FuzzContext) -> list[str]:
    """Exactly the same findings: every field, message text and order included."""
    single = run(scenario, ctx.settings, batching=False)
    runs = run(scenario, ctx.settings, batching=True)
    return [
        f"one at a time: {a}; as runs: {b}"
        for a, b in itertools.zip_longest(single, runs)
        if a != b
    ][:3]


@dataclass(frozen=True, slots=True)
class PropertySpec:
    name: str
    check: Property
    claim: str
    fails: bool = True
    """False for the counting property (b): it reports, never fails."""
    uses_files: bool = False


PROPERTIES: dict[str, PropertySpec] = {
    p.name: p
    for p in (
        PropertySpec(
            "explained",
            every_unintended_outcome_is_explained,
            "every outcome the gate model predicts that the stream did not intend is explained "
            "by a finding",
        ),
        PropertySpec(
            "docs-stricter",
            docs_stricter_rules_are_counted,
            "doc rules the gate accepts are counted (docs stricter than code)",
            fails=False,
        ),
        PropertySpec(
            "round-trip",
            recordings_round_trip,
            "a stream written with the writers and read back gives the same events and findings",
            uses_files=True,
        ),
        PropertySpec(
            "truncation",
            truncated_recordings_give_a_prefix,
            "a recording cut at any byte lints without an exception, findings a prefix",
            uses_files=True,
        ),
        PropertySpec(
            "invariants",
            gate_invariants_hold,
            "the gate model keeps its invariants (docs/fuzz.md)",
        ),
        PropertySpec(
            "runs",
            runs_match_single_messages,
            "checks given the stream as runs report what they report one message at a time",
        ),
    )
}
