"""Run a campaign: one Hypothesis search per property, seeded, shrunk, timed.

Determinism: the examples come from ``@seed(seed)`` with Hypothesis's example database off (the
``ci`` profile; reproducers survive as committed files instead), so a seed and an example count
give the same examples and the same counterexample on every machine. A time budget stops the
search early (at the same example sequence, later or sooner depending on the machine).

The search is steered with ``target()`` toward the gate's thresholds: the largest keep-alive gap
toward the loss timeout, the keep-alive before the switch toward the documented 1 s.
"""

from __future__ import annotations

import contextlib
import itertools
import re
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import field
from typing import Any

from hypothesis import HealthCheck, Phase, given, seed, settings, target
from hypothesis import strategies as st
from hypothesis.configuration import set_hypothesis_home_dir
from hypothesis.errors import Found

from fuzzoff.config import Settings
from fuzzoff.events import Command, is_keepalive
from fuzzoff.fuzz.mutate import mutations
from fuzzoff.fuzz.properties import PROPERTIES, FuzzContext, PropertySpec
from fuzzoff.fuzz.scenario import Scenario, TransportName
from fuzzoff.fuzz.streams import scenarios
from fuzzoff.gate.params import default_params, loss_timeout
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.releases import PX4Profile

PROFILE_CI = "fuzzoff-ci"
settings.register_profile(
    PROFILE_CI,
    database=None,
    deadline=None,
    print_blob=False,
    suppress_health_check=list(HealthCheck),
    report_multiple_bugs=False,
)


class _Stop(BaseException):
    """Raised inside the test to end the search when the budget is spent (a BaseException, so
    Hypothesis does not take it for a failure)."""


@dataclass(slots=True)
class PropertyResult:
    name: str
    claim: str
    examples: int = 0
    seconds: float = 0.0
    model_seconds: float = 0.0
    """Time inside the property (gate model, rules, writers), the rest is generation."""
    failed: bool = False
    problems: list[str] = field(default_factory=list)
    counterexample: Scenario | None = None
    cut_fraction: float | None = None
    found_after: int | None = None
    """The first failing example: the how-manieth of the search."""
    failed_examples: int = 0
    """How many of the examples failed (only the first is shrunk and reported)."""
    shrinks: int = 0
    """The examples Hypothesis tried while shrinking the first failure (not in ``examples``)."""
    found_seconds: float | None = None
    counts: dict[str, dict[str, int]] = field(default_factory=dict)
    started: float = 0.0
    known: dict[str, int] = field(default_factory=dict)
    """Known problems seen (pattern -> examples), when the campaign filters them."""
    reached: dict[str, int] = field(default_factory=dict)
    """Rule code -> the examples it gave a finding on, for the properties that lint the
    stream (``explained``, ``docs-stricter``): which rules the campaign's streams reach."""

    def seconds_so_far(self) -> float:
        return time.perf_counter() - self.started

    def to_json(self) -> dict[str, Any]:
        return {
            "property": self.name,
            "claim": self.claim,
            "examples": self.examples,
            "seconds": round(self.seconds, 3),
            "examples_per_s": round(self.examples / self.seconds, 1) if self.seconds else None,
            "model_seconds": round(self.model_seconds, 3),
            "failed": self.failed,
            "problems": self.problems,
            "failed_examples": self.failed_examples,
            "shrink_steps": self.shrinks,
            "found_after_examples": self.found_after,
            "found_after_seconds": None
            if self.found_seconds is None
            else round(self.found_seconds, 3),
            "counterexample": None
            if self.counterexample is None
            else self.counterexample.describe(),
            "counts": self.counts,
            "known": self.known,
            "reached": self.reached,
        }


@dataclass(slots=True)
class CampaignConfig:
    px4: PX4Profile | None = None
    vehicle: str | None = None
    transport: TransportName | None = None
    examples: int | None = 200
    budget_s: float | None = None
    seed: int = 0
    properties: tuple[str, ...] = tuple(PROPERTIES)
    settings: Settings = field(default_factory=Settings)
    shrink_s: float = 30.0
    """How long shrinking a counterexample may take at most."""
    known: tuple[str, ...] = ()
    """Regular expressions of known problems (``fuzz.known``): left out, so the search goes on
    for new ones; each one's count is in ``PropertyResult.known``."""
    base: Scenario | None = None
    """``--from``: mutate this scenario (a user's recording) instead of drawing new streams."""
    base_problems: list[str] = field(default_factory=list)
    """The parts of the ``--from`` recording that could not be read (``base`` is the part
    before them), one line each as ``fuzzoff lint`` reports them."""
    seeds: tuple[int, ...] = ()
    """``--seeds``: the campaign was run once per seed (``fuzzoff.fleet.fuzz_run``) and its
    result merged; ``seed`` is then the first of them."""


def _targets(scenario: Scenario) -> None:
    """Steer toward the thresholds: gap vs loss timeout, stream length before the switch."""
    timeout = loss_timeout(scenario.px4, default_params(scenario.px4) | dict(scenario.params))
    keep = [e.t for e in scenario.events if is_keepalive(e)]
    if len(keep) >= 2:
        gap = max(b - a for a, b in itertools.pairwise(keep))
        target(-abs(gap - timeout), label="gap near the loss timeout")
    switch = next(
        (e.t for e in scenario.events if isinstance(e, Command) and e.is_offboard_switch), None
    )
    if switch is not None and keep:
        before = switch - keep[0] if keep[0] <= switch else 0.0
        target(-abs(before - 1.0), label="keep-alive before the switch near 1 s")


def run_property(
    spec: PropertySpec,
    config: CampaignConfig,
    budget_s: float | None,
    on_example: Callable[[PropertyResult], None] | None = None,
) -> PropertyResult:
    """Check ``spec`` on the examples asked (``config.examples``, or as many as the budget
    allows), all of them: a counterexample does not end the search. Then, when one failed, the
    same seed again up to the first failing example, where Hypothesis stops and shrinks it (the
    examples before it are the same: Hypothesis chooses each from the results before it)."""
    result = PropertyResult(spec.name, spec.claim)
    ctx = FuzzContext(settings=config.settings, recorded_answers=config.base is not None)
    result.started = time.perf_counter()
    known = [re.compile(k) for k in config.known]
    first: dict[str, Any] = {}

    def search(example: tuple[Scenario, float]) -> None:
        if budget_s is not None and time.perf_counter() - result.started > budget_s:
            raise _Stop
        result.examples += 1
        problems = _checked(spec, example, ctx, known, result)
        if on_example is not None:
            on_example(result)
        if problems and spec.fails:
            result.failed_examples += 1
            if not first:
                first.update(scenario=example[0], cut=example[1], problems=problems)
                result.found_after = result.examples
                result.found_seconds = time.perf_counter() - result.started

    try:
        _hypothesis(search, config, config.examples)
        result.reached = dict(sorted(ctx.reached.items()))  # the search's, not the shrinking's
        if first:
            _shrink(spec, config, ctx, known, result, first)
    finally:
        result.seconds = time.perf_counter() - result.started
        ctx.close()
    if first:
        result.failed = True
        result.problems = list(first["problems"])
        result.counterexample = first["scenario"]
        result.cut_fraction = first["cut"] if spec.name == "truncation" else None
    if spec.name == "docs-stricter":
        result.counts = {
            code: {"fired": ctx.docs_fired[code], "gate_accepted": ctx.docs_stricter[code]}
            for code in sorted(ctx.docs_fired)
        }
    return result


def _checked(
    spec: PropertySpec,
    example: tuple[Scenario, float],
    ctx: FuzzContext,
    known: list[re.Pattern[str]],
    result: PropertyResult,
) -> list[str]:
    """The property's problems on one example, the known ones left out (and counted)."""
    scenario, cut = example
    _targets(scenario)
    ctx.cut_fraction = cut
    t0 = time.perf_counter()
    problems = spec.check(scenario, ctx)
    result.model_seconds += time.perf_counter() - t0
    if known and problems:
        problems = _unknown(problems, known, result.known)
    return problems


def _shrink(
    spec: PropertySpec,
    config: CampaignConfig,
    ctx: FuzzContext,
    known: list[re.Pattern[str]],
    result: PropertyResult,
    first: dict[str, Any],
) -> None:
    """The search again with the same settings (Hypothesis's schedule depends on the example
    count asked), failing at the first counterexample so that Hypothesis shrinks it: ``first``
    becomes the shrunk one. Known problems are not counted twice. Should the search not meet
    the failure where the first pass did, ``first`` stays as it was found, unshrunk."""
    failing: dict[str, float] = {}
    seen: dict[str, int] = {}
    calls = 0

    def again(example: tuple[Scenario, float]) -> None:
        nonlocal calls
        if failing:
            if time.perf_counter() - failing["at"] > config.shrink_s:
                raise _Stop
            result.shrinks += 1
        else:
            calls += 1
            if calls > (result.found_after or 0):
                raise _Stop
        saved, result.known = result.known, seen
        try:
            problems = _checked(spec, example, ctx, known, result)
        finally:
            result.known = saved
        if problems:
            failing.setdefault("at", time.perf_counter())
            first.update(scenario=example[0], cut=example[1], problems=problems)
            raise AssertionError("\n".join(problems))

    _hypothesis(again, config, config.examples)


def _hypothesis(
    check: Callable[[tuple[Scenario, float]], None], config: CampaignConfig, examples: int | None
) -> None:
    """Run ``check`` on the campaign's examples under its seed (at most ``examples``)."""
    streams = (
        scenarios(config.px4, config.vehicle, config.transport)
        if config.base is None
        else mutations(config.base)
    )
    test = given(st.tuples(streams, st.floats(0.0, 1.0)))(check)
    test = settings(
        settings.get_profile(PROFILE_CI),
        max_examples=examples if examples is not None else 10**9,
        phases=(Phase.generate, Phase.target, Phase.shrink),
    )(test)
    test = seed(config.seed)(test)
    with contextlib.suppress(_Stop, AssertionError, Found):
        test()


@dataclass(slots=True)
class CampaignResult:
    config: CampaignConfig
    results: list[PropertyResult]

    @property
    def failed(self) -> bool:
        return any(r.failed for r in self.results)

    @property
    def examples(self) -> int:
        return sum(r.examples for r in self.results)

    @property
    def unchecked(self) -> list[str]:
        """The properties no example was checked on (a time budget spent before the first)."""
        return [r.name for r in self.results if r.examples == 0]

    @property
    def seconds(self) -> float:
        return sum(r.seconds for r in self.results)


def _unknown(problems: list[str], known: list[re.Pattern[str]], seen: dict[str, int]) -> list[str]:
    out = []
    for p in problems:
        hit = next((k for k in known if k.search(p)), None)
        if hit is None:
            out.append(p)
        else:
            seen[hit.pattern] = seen.get(hit.pattern, 0) + 1
    return out


def run_campaign(
    config: CampaignConfig,
    on_example: Callable[[PropertyResult], None] | None = None,
    on_property: Callable[[PropertyResult], None] | None = None,
) -> CampaignResult:
    """Every selected property in turn, the time budget split evenly between them."""
    share = None if config.budget_s is None else config.budget_s / len(config.properties)
    results = []
    with _hypothesis_storage():
        for name in config.properties:
            result = run_property(PROPERTIES[name], config, share, on_example)
            results.append(result)
            if on_property is not None:
                on_property(result)
    return CampaignResult(config, results)


@contextlib.contextmanager
def _hypothesis_storage() -> Iterator[None]:
    """Hypothesis's storage directory in a temporary folder, removed afterwards. With the
    example database off, Hypothesis still caches there what it reads from the source of local
    modules (``.hypothesis/constants``) and its Unicode tables; by default that is
    ``.hypothesis/`` in the working folder, where fuzzoff must write nothing. Afterwards the
    default is back (``HYPOTHESIS_STORAGE_DIRECTORY``, else the working folder)."""
    with tempfile.TemporaryDirectory(prefix="fuzzoff-hypothesis-") as folder:
        set_hypothesis_home_dir(folder)
        try:
            yield
        finally:
            set_hypothesis_home_dir(None)


def counts_total(results: list[PropertyResult]) -> Counter[str]:
    total: Counter[str] = Counter()
    for r in results:
        for code, c in r.counts.items():
            total[code] += c["gate_accepted"]
    return total
