"""A fleet's lint, run where it is asked to: every recording by ``lint_file`` (or the function
given), on a Dask cluster (``--scheduler``) or in this machine's processes, each outcome handed
on as it comes. The command's half (its options, the recordings named on the command line, the
reports and the Parquet dataset) is ``commands/_lint_fleet.py``.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from concurrent.futures import ProcessPoolExecutor
from functools import partial

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.fleet.task import Lint, Outcome, lint_target


def lint_all(
    plan: Sequence[tuple[str, Settings]],
    *,
    scheduler: str | None,
    jobs: int = 1,
    timeout_s: float | None = None,
    lint: Lint = lint_file,
    known: Collection[str] = (),
    record: bool = False,
    on_outcome: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    """Every target's outcome, in the order of ``plan`` (each target with the settings it is
    judged with, resolved by the command): on the Dask cluster at ``scheduler`` (``local``
    starts one with ``jobs`` worker processes, as many as ``--jobs`` would use), else in
    ``jobs`` processes here."""
    targets = [target for target, _ in plan]
    if scheduler is not None:
        from fuzzoff.fleet.cluster import DEFAULT_TIMEOUT_S, connect, run_on_cluster

        with connect(scheduler, jobs) as client:
            return run_on_cluster(
                client,
                targets,
                [settings for _, settings in plan],
                timeout_s=timeout_s or DEFAULT_TIMEOUT_S,
                lint=lint,
                known=known,
                record=record,
                on_outcome=on_outcome,
            )
    work = partial(_lint_here, lint=lint, record=record)
    outcomes: list[Outcome] = []
    if jobs > 1 and len(plan) > 1:
        with ProcessPoolExecutor(jobs, initializer=_know, initargs=(frozenset(known),)) as pool:
            for outcome in pool.map(work, plan):
                outcomes.append(outcome)
                if on_outcome is not None:
                    on_outcome(outcome)
        return outcomes
    _know(frozenset(known))
    for planned in plan:
        outcome = work(planned)
        outcomes.append(outcome)
        if on_outcome is not None:
            on_outcome(outcome)
    return outcomes


_KNOWN: frozenset[str] = frozenset()
"""The dataset's hashes in a local worker process (set once by the pool's initializer, not
sent with every recording)."""


def _know(known: frozenset[str]) -> None:
    global _KNOWN
    _KNOWN = known


def _lint_here(planned: tuple[str, Settings], *, lint: Lint, record: bool) -> Outcome:
    target, settings = planned
    return lint_target(target, settings, lint=lint, known=_KNOWN, record=record)
