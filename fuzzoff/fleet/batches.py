"""Recordings grouped into Dask tasks by their bytes, so that a task is about a second of work.

A Dask task costs the client and the scheduler a few milliseconds whatever it does; a small
recording lints in tens of milliseconds, so one task per recording spends a fifth of the run on
Dask. A task that lints several recordings in turn pays that once for all of them. A task's
work is estimated from its recordings' sizes (``cost_s``); a recording larger than a task's
budget is a task of its own, as every recording was before.

Tasks are planned largest first and shrink toward the end of the run (a task takes at most a
``GUIDED`` share of the work left per worker, as in guided self-scheduling), so that no worker
is left with a full second of work while the others have finished.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

TASK_S = 1.0
"""The work one task is sized to, in seconds of one core."""
FILE_S = 0.02
"""What a recording costs whatever its size (opening it, finding its format, building its
reader and profile, its report): a small MCAP or ROS 2 bag spends most of its lint there."""
BYTES_PER_S = 5e6
"""Bytes linted in a second beyond that. With ``FILE_S``, the estimate is within about 2x of
the lint of each format of the bench's recordings (``python -m bench fleet``), over rather than
under on most (a small ULog lints in a third of its estimate); a real flight's ULog lints at
about 60 MB/s, so a task of real flights is shorter than planned, never longer."""
GUIDED = 4
"""A task takes at most 1/(GUIDED x workers) of the work not yet planned."""


def cost_s(size: int | None) -> float:
    """The estimated seconds of one recording of ``size`` bytes (None: unknown, a task of its
    own)."""
    if size is None:
        return TASK_S
    return FILE_S + size / BYTES_PER_S


def recording_bytes(target: str) -> int | None:
    """A local recording's bytes (a bag folder: its files'); None for a URL or what cannot be
    read (its lint says why)."""
    path = Path(target)
    try:
        if path.is_dir():
            return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
        return path.stat().st_size
    except OSError:
        return None


def plan(sizes: Sequence[int | None], workers: int) -> list[tuple[int, ...]]:
    """The tasks for recordings of ``sizes`` bytes on ``workers`` workers: runs of consecutive
    indices (so outcomes come back near the order of the recordings), each at most
    ``TASK_S`` of estimated work and at most its share of the work left; a recording over
    that is a task alone."""
    costs = [cost_s(s) for s in sizes]
    left = sum(costs)
    share = GUIDED * max(1, workers)
    tasks: list[tuple[int, ...]] = []
    current: list[int] = []
    budget = 0.0
    spent = 0.0
    for i, cost in enumerate(costs):
        if current and spent + cost > budget:
            tasks.append(tuple(current))
            current = []
        if not current:
            budget = min(TASK_S, left / share)
            spent = 0.0
        current.append(i)
        spent += cost
        left -= cost
    if current:
        tasks.append(tuple(current))
    return tasks
