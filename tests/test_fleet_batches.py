"""Several small recordings to a Dask task, sized by their bytes (``fuzzoff.fleet.batches``):
every recording in exactly one task, in order, big ones alone, small tasks at the end of the run
so no worker is left with a long one while the others wait. The failures inside a batch are in
``test_fleet_cluster``."""

from __future__ import annotations

from fuzzoff.fleet.batches import TASK_S, cost_s, plan, recording_bytes
from fuzzoff.formats import find_recordings
from tests.helpers import CORPORA

KB = 1000
MB = 1000 * KB


def _flat(tasks: list[tuple[int, ...]]) -> list[int]:
    return [i for task in tasks for i in task]


def test_every_recording_once_in_order() -> None:
    sizes = [100 * KB + (i * 37) % 200 * KB for i in range(1000)]
    tasks = plan(sizes, workers=2)
    assert _flat(tasks) == list(range(1000))
    assert all(sum(cost_s(sizes[i]) for i in t) <= TASK_S + 1e-9 for t in tasks)
    # a thousand recordings of about 0.03 s each: far fewer tasks than recordings
    assert len(tasks) < 100


def test_a_recording_over_the_budget_and_one_of_unknown_size_are_tasks_alone() -> None:
    sizes: list[int | None] = [100 * KB] * 40 + [60 * MB] + [100 * KB] * 40 + [None] + [1 * KB]
    tasks = plan(sizes, workers=1)
    assert (40,) in tasks
    assert (81,) in tasks
    assert _flat(tasks) == list(range(len(sizes)))


def test_tasks_shrink_toward_the_end_of_the_run() -> None:
    sizes = [200 * KB] * 2000
    tasks = plan(sizes, workers=4)
    assert len(tasks[0]) > 10 * len(tasks[-1])
    assert len(tasks[-1]) == 1


def test_the_corpus_is_planned_into_fewer_tasks_than_recordings() -> None:
    recordings = [str(p) for p in find_recordings(CORPORA)]
    sizes = [recording_bytes(r) for r in recordings]
    assert None not in sizes
    tasks = plan(sizes, workers=2)
    assert _flat(tasks) == list(range(len(recordings)))
    assert len(tasks) < len(recordings) / 3


def test_a_url_has_no_size_here(tmp_path: object) -> None:
    assert recording_bytes("s3://bucket/flight.ulg") is None
    assert recording_bytes("/no/such/file.ulg") is None
