"""Fuzz effectiveness (issue 7): does a campaign find each known hazard class, and how fast?

Each class is planted one of two ways:

* ``fault``: the rules that should explain the hazard are switched off (``Settings.ignore``, a
  faulty copy of the rules), so property (a) must fail with that hazard; found = the campaign's
  first counterexample naming it;
* ``target``: the campaign must reach the region where a rule fires (found = the first example
  on which that rule reports), for classes the gate model has no transition for.

Target: every class found within 60 s on the 2-core machine. Also: examples/s of a default
campaign and the share of its time spent in the gate model + rules (the property) versus in
Hypothesis's generation (target: model + rules < generation). ``python -m bench fuzz``.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from fuzzoff.config import Settings
from fuzzoff.fuzz.campaign import CampaignConfig, _Stop, run_property
from fuzzoff.fuzz.hazards import EXPLAINED_BY
from fuzzoff.fuzz.known import KNOWN
from fuzzoff.fuzz.properties import (
    PROPERTIES,
    FuzzContext,
    PropertySpec,
    every_unintended_outcome_is_explained,
)
from fuzzoff.fuzz.scenario import Scenario, TransportName, run

BUDGET_S = 60.0
SEED = 1
SEEDS = (1, 2, 3)
"""Each class is searched once per seed: a search is chaotic, the worst seed is the figure."""


@dataclass(frozen=True, slots=True)
class HazardClass:
    name: str
    how: str
    """``fault`` (rules switched off, property (a) must fail) or ``target`` (a rule fires)."""
    pattern: str = ""
    """fault: the problem text naming the hazard."""
    ignore: frozenset[str] = frozenset()
    rule: str = ""
    """target: the rule whose finding marks the region."""
    px4: str | None = None
    vehicle: str | None = None
    transport: TransportName | None = None
    extra: dict[str, str] = field(default_factory=dict)


CLASSES: tuple[HazardClass, ...] = (
    HazardClass(
        "too-short stream before the switch",
        "fault",
        r"request_rejected",
        EXPLAINED_BY["request_rejected"],
        px4="1.13",
        vehicle="mc",
        transport="ros2",
    ),
    HazardClass(
        "keep-alive gap just over the loss timeout",
        "fault",
        r"failsafe",
        EXPLAINED_BY["failsafe"],
        px4="1.15",
        vehicle="mc",
        transport="ros2",
    ),
    HazardClass(
        "setpoints outside offboard (none after the switch)",
        "fault",
        r"controller .*no TrajectorySetpoint since",
        EXPLAINED_BY["controller"],
        px4="1.15",
        vehicle="mc",
        transport="ros2",
    ),
    HazardClass(
        "NaN pattern selecting another controller",
        "fault",
        r"controller .*has no finite position",
        EXPLAINED_BY["controller"],
        px4="1.16",
        vehicle="mc",
        transport="ros2",
    ),
    HazardClass(
        "x/y not paired",
        "fault",
        r"x and y are not both finite",
        EXPLAINED_BY["controller"],
        px4="1.15",
        vehicle="mc",
        transport="ros2",
    ),
    HazardClass(
        "unsupported frame",
        "fault",
        r"setpoint_dropped .*coordinate frame",
        EXPLAINED_BY["setpoint_dropped"],
        px4="1.15",
        vehicle="mc",
        transport="mavlink",
    ),
    HazardClass(
        "fixed-wing without setpoint type",
        "target",
        rule="OFB603",
        vehicle="fw",
        px4="1.15",
        transport="mavlink",
    ),
    HazardClass(
        "rover combination without its NaN setpoint",
        "target",
        rule="OFB504",
        px4="1.17",
        vehicle="rover-differential",
        transport="ros2",
    ),
    HazardClass("clock skew", "target", rule="OFB106", px4="1.15", transport="ros2"),
    HazardClass("frozen setpoint", "target", rule="OFB107", px4="1.15", transport="ros2"),
)


def _fault_check(pattern: str) -> Callable[[Scenario, FuzzContext], list[str]]:
    rx = re.compile(pattern)

    def check(scenario: Scenario, ctx: FuzzContext) -> list[str]:
        ctx.first_only = False
        return [p for p in every_unintended_outcome_is_explained(scenario, ctx) if rx.search(p)]

    return check


def _target_check(code: str) -> Callable[[Scenario, FuzzContext], list[str]]:
    def check(scenario: Scenario, ctx: FuzzContext) -> list[str]:
        return [
            f"{f.code} fires: {f.message}"
            for f in run(scenario, ctx.settings)
            if f.code == code  # at any severity: OFB603 is info where every release accepts
        ][:1]

    return check


def _until_found(
    check: Callable[[Scenario, FuzzContext], list[str]],
) -> Callable[[Scenario, FuzzContext], list[str]]:
    """``check``, ending the search at its first problem: a campaign goes on to the end of its
    budget (every example is checked), but this benchmark asks only how soon a class is found,
    and would otherwise spend the whole 60 s on every class and seed."""
    found = False

    def first(scenario: Scenario, ctx: FuzzContext) -> list[str]:
        nonlocal found
        if found:
            raise _Stop
        problems = check(scenario, ctx)
        found = bool(problems)
        return problems

    return first


def measure(cls: HazardClass, seed: int = SEED) -> tuple[bool, int, float]:
    check = _fault_check(cls.pattern) if cls.how == "fault" else _target_check(cls.rule)
    spec = PropertySpec(cls.name, _until_found(check), cls.name)
    config = CampaignConfig(
        px4=cls.px4,
        vehicle=cls.vehicle,
        transport=cls.transport,
        examples=None,
        seed=seed,
        settings=Settings(ignore=cls.ignore),
        shrink_s=0.0,
    )
    result = run_property(spec, config, BUDGET_S)
    if not result.failed:
        return False, result.examples, result.seconds
    return True, result.found_after or 0, result.found_seconds or 0.0


def throughput(examples: int = 400) -> tuple[int, float, float]:
    config = CampaignConfig(examples=examples, seed=SEED, shrink_s=0.0, known=tuple(KNOWN))
    result = run_property(PROPERTIES["explained"], config, None)
    return result.examples, result.seconds, result.model_seconds


def main() -> None:
    print(f"{'hazard class':<50} {'planted':<8} {'seeds':>5} {'examples':>18} {'seconds':>18}")
    print(f"{'':<50} {'':<8} {'found':>5} {'median / worst':>18} {'median / worst':>18}")
    all_found = True
    for cls in CLASSES:
        runs = [measure(cls, seed) for seed in SEEDS]
        found = sum(1 for f, _, s in runs if f and s <= BUDGET_S)
        all_found = all_found and found == len(SEEDS)
        ex = sorted(e for _, e, _ in runs)
        sec = sorted(s for _, _, s in runs)
        how = cls.how if cls.how == "fault" else f"{cls.rule}"
        mid = len(SEEDS) // 2
        print(
            f"{cls.name:<50} {how:<8} {found:>2}/{len(SEEDS)} {ex[mid]:>8} / {ex[-1]:>7} "
            f"{sec[mid]:>8.2f} / {sec[-1]:>7.2f}"
        )
    start = time.perf_counter()
    n, seconds, model = throughput()
    wall = time.perf_counter() - start
    generation = seconds - model
    print()
    print(f"default campaign (property 'explained'): {n} examples in {seconds:.2f} s ")
    print(f"  {n / seconds:.1f} examples/s (wall {wall:.2f} s)")
    print(f"  gate model + rules: {model:.2f} s ({100 * model / seconds:.0f} %)")
    print(f"  Hypothesis generation and shrinking: {generation:.2f} s")
    print()
    print("target                                              ok")
    print(f"every class found within {BUDGET_S:.0f} s (every seed)           {all_found}")
    print(f"model + rules take less time than generation       {model < generation}")


if __name__ == "__main__":
    main()
