"""``fuzzoff fuzz --seeds 0-199 [--scheduler ADDRESS]``: one seeded campaign per seed, as Dask
tasks (or in turn here), merged into one campaign.

Each task runs exactly what ``fuzzoff fuzz --seed N`` runs (the same examples and budget), so
any seed's counterexample is reproduced by that command alone. Counterexamples are the same
when their shrunk scenarios are (same events, profile, transport and parameters): the merged
result keeps, per property, the one from the lowest seed and names every other distinct one
with its seed; the copies are counted.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import os
import re
import threading
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any

from fuzzoff.config import ConfigError
from fuzzoff.fuzz.campaign import CampaignConfig, CampaignResult, PropertyResult, run_campaign
from fuzzoff.fuzz.scenario import Scenario

MAX_SEEDS = 100_000
_CAMPAIGN_LOCK = threading.Lock()
"""Hypothesis keeps global state per process: a worker with several threads runs one
campaign at a time."""


def parse_seeds(text: str) -> tuple[int, ...]:
    """``0-199``, ``3,7,11`` or a mix (``0-9,42``): the seeds in order, each once."""
    seeds: list[int] = []
    for part in text.split(","):
        match = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if match is None:
            raise ConfigError(f"--seeds {text!r}: expected FIRST-LAST or seeds with commas")
        first = int(match.group(1))
        last = int(match.group(2)) if match.group(2) is not None else first
        if last < first:
            raise ConfigError(f"--seeds {text!r}: {first}-{last} runs backwards")
        if last - first >= MAX_SEEDS or len(seeds) + last - first >= MAX_SEEDS:
            raise ConfigError(f"--seeds {text!r}: at most {MAX_SEEDS} seeds")
        seeds.extend(range(first, last + 1))
    return tuple(dict.fromkeys(seeds))


def one_seed(config: CampaignConfig, seed: int) -> CampaignResult:
    """The task: the campaign with this seed (no progress callbacks: they stay here)."""
    with _CAMPAIGN_LOCK:
        return run_campaign(dataclasses.replace(config, seed=seed, seeds=()))


def run_seeds(
    config: CampaignConfig,
    seeds: Sequence[int],
    scheduler: str | None,
    on_seed: Callable[[int], None] | None = None,
    workers: int = 0,
) -> tuple[CampaignResult, list[str]]:
    """Every seed's campaign, merged; and one line per seed whose campaign did not finish (a
    worker that died, fuzzoff raising): the merged result is then of the others. ``workers``:
    for ``--scheduler local`` (default one per core: fuzz has no ``--jobs``)."""
    results: dict[int, CampaignResult] = {}
    unfinished: list[str] = []
    if scheduler is None:
        for seed in seeds:
            results[seed] = one_seed(config, seed)
            if on_seed is not None:
                on_seed(seed)
    else:
        from distributed import as_completed

        from fuzzoff.fleet.cluster import connect

        with connect(scheduler, workers or os.cpu_count() or 1) as client:
            futures = {
                client.submit(one_seed, config, seed, key=f"fuzzoff-fuzz-{seed}", pure=False): seed
                for seed in seeds
            }
            for future in as_completed(futures):
                seed = futures[future]
                if future.status == "finished":
                    results[seed] = future.result()
                else:
                    exc: Any = future.exception()
                    what = f"{type(exc).__name__}: {exc}"
                    unfinished.append(f"seed {seed}: the campaign did not finish ({what})")
                future.release()
                if on_seed is not None:
                    on_seed(seed)
    ordered = [results[s] for s in seeds if s in results]
    merged_config = dataclasses.replace(config, seed=seeds[0], seeds=tuple(seeds))
    return merge(merged_config, ordered, [s for s in seeds if s in results]), unfinished


def content_key(scenario: Scenario) -> str:
    """Two counterexamples are the same when their shrunk scenarios are."""
    text = json.dumps(scenario.to_json(), sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def merge(
    config: CampaignConfig, results: Sequence[CampaignResult], seeds: Sequence[int]
) -> CampaignResult:
    """One campaign: per property, examples and times added, counts added, the first
    counterexample kept and the other distinct ones named with their seed."""
    merged: list[PropertyResult] = []
    for name in config.properties:
        runs = [
            (seed, r)
            for seed, c in zip(seeds, results, strict=True)
            for r in c.results
            if r.name == name
        ]
        if not runs:
            continue
        merged.append(_merge_property(runs))
    return CampaignResult(config, merged)


def _merge_property(runs: list[tuple[int, PropertyResult]]) -> PropertyResult:
    first = runs[0][1]
    out = PropertyResult(first.name, first.claim)
    counts: dict[str, Counter[str]] = {}
    known: Counter[str] = Counter()
    distinct: dict[str, tuple[int, PropertyResult]] = {}
    copies: Counter[str] = Counter()
    for seed, r in runs:
        out.examples += r.examples
        out.seconds += r.seconds
        out.model_seconds += r.model_seconds
        out.failed_examples += r.failed_examples
        out.shrinks += r.shrinks
        known.update(r.known)
        for code, c in r.counts.items():
            counts.setdefault(code, Counter()).update(c)
        if r.failed:
            key = f"seed {seed}" if r.counterexample is None else content_key(r.counterexample)
            copies[key] += 1
            distinct.setdefault(key, (seed, r))
    out.counts = {code: dict(c) for code, c in sorted(counts.items())}
    out.known = dict(known)
    if distinct:
        (seed, r), *others = distinct.values()
        out.failed = True
        out.counterexample = r.counterexample
        out.cut_fraction = r.cut_fraction
        out.found_after = r.found_after
        out.found_seconds = r.found_seconds
        key = f"seed {seed}" if r.counterexample is None else content_key(r.counterexample)
        out.problems = [*r.problems, _found_by(seed, copies[key])]
        for other_seed, other in others:
            ce = other.counterexample
            n = copies[f"seed {other_seed}" if ce is None else content_key(ce)]
            shown = "" if ce is None else f"{ce.describe()}: "
            out.problems.append(
                f"another counterexample ({_found_by(other_seed, n)}): "
                f"{shown}{'; '.join(other.problems)}"
            )
    return out


def _found_by(seed: int, copies: int) -> str:
    also = ""
    if copies > 1:
        also = f", and by {copies - 1} other seed{'s' if copies > 2 else ''} shrunk to the same"
    return f"found by seed {seed} (fuzzoff fuzz --seed {seed}){also}"


def run_seeds_of(
    args: argparse.Namespace, config: CampaignConfig
) -> tuple[CampaignResult, list[str]]:
    """``fuzzoff fuzz`` with ``--seeds`` (which replaces ``--seed``) and/or ``--scheduler``; a
    progress bar of the seeds on a terminal's standard error."""
    seeds = parse_seeds(args.seeds) if args.seeds is not None else (config.seed,)
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
    )

    console = Console(stderr=True)
    if args.quiet or not console.is_terminal or len(seeds) < 2:
        return run_seeds(config, seeds, args.scheduler)
    columns = (TextColumn("fuzz seeds"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task("seeds", total=len(seeds))
        return run_seeds(config, seeds, args.scheduler, lambda _: bar.update(task, advance=1))
