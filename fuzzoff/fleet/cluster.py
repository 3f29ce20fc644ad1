"""Recordings as Dask tasks: one task per recording, results as they finish, no recording able
to end the run.

A worker process that dies while linting (a crash in a reader's C code, the kernel's OOM
killer) is restarted by its nanny and the scheduler tries the recording again elsewhere; when
it has killed ``allowed-failures`` + 1 workers the scheduler gives up on it (``KilledWorker``)
and it becomes that recording's OFB001. A recording that runs past ``--timeout`` is stopped
the only way a thread can be: its task is cancelled and its worker process ended, and the
worker's nanny starts a new one. The clock runs
from the moment the task starts on its worker (each task announces itself with
``Worker.log_event``), not from its submission, so a long queue does not time anything out.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import os
import threading
import time
import uuid
from collections.abc import Callable, Collection, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from fuzzoff.config import ConfigError, Settings
from fuzzoff.engine import lint_file
from fuzzoff.fleet import require
from fuzzoff.fleet.task import CRASHED, FAILED, TIMED_OUT, Lint, Outcome, failed_report, lint_target

LOCAL = "local"
DEFAULT_TIMEOUT_S = 600.0
"""Per recording. A 1M-message recording lints in about 10 s on one core; ten minutes is a
recording fuzzoff cannot finish, not a slow one."""
LOCAL_ALLOWED_FAILURES = 1
"""For ``--scheduler local``: a recording that killed two worker processes in turn is the
cause, not the machine (Dask's default, 3, restarts four workers before it says so). A remote
scheduler keeps its own ``distributed.scheduler.allowed-failures``."""
EXIT_STOPPED = 75
"""Exit status of a worker process ended because a recording ran past the timeout."""
WATCH_S = 0.5
"""How often the watchdog looks for tasks past the timeout."""
BYSTANDER_TRIES = 3
"""Submissions of a recording whose task died with workers that another task killed (it was
queued there, or its start was not heard before the worker died): the first, and two more."""


@contextmanager
def connect(address: str, workers: int = 1) -> Iterator[Any]:
    """A ``distributed.Client`` for ``address``: a scheduler's address (``tcp://host:8786``),
    or ``local`` for a LocalCluster on this machine with ``workers`` single-threaded worker
    processes (``--jobs``, as for the local processes without Dask)."""
    require("scheduler", "--scheduler")
    from distributed import Client

    # Dask logs a worker it restarts as a warning with a traceback; the run says it in one line
    logging.getLogger("distributed").setLevel(logging.ERROR)
    if address == LOCAL:
        with local_cluster(workers) as cluster, Client(cluster) as client:
            yield client
        return
    try:
        client = Client(address, timeout="20s")
    except (OSError, TimeoutError, ValueError) as exc:
        reason = f"cannot reach the Dask scheduler ({exc})"
        raise ConfigError(f"--scheduler {address}: {reason}") from None
    with client:
        yield client


def local_cluster(workers: int) -> Any:
    """A LocalCluster of ``workers`` single-threaded worker processes, each with a nanny."""
    import dask
    from distributed import LocalCluster

    local = {
        "distributed.scheduler.allowed-failures": LOCAL_ALLOWED_FAILURES,
        # one task on a worker at a time: a worker that dies takes no queued recording along
        "distributed.scheduler.worker-saturation": 1.0,
        # with one task per worker there is nothing to steal, and the statistical profiler
        # (a stack sample every 10 ms) and the 20 ms event-loop tick in every process cost
        # CPU time all the run long, which --jobs does not pay
        "distributed.scheduler.work-stealing": False,
        "distributed.worker.profile.enabled": False,
        "distributed.admin.tick.interval": "1s",
    }
    with dask.config.set(local):
        return LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # any free port: no warning when 8787 is taken
            silence_logs=logging.ERROR,
        )


def _run(
    index: int,
    target: str,
    settings: Settings,
    topic: str,
    lint: Lint,
    known: Collection[str],
    record: bool,
) -> Outcome:
    """The task: say it started (the timeout's clock), then lint."""
    from distributed import get_worker

    worker = get_worker()
    worker.log_event(topic, {"index": index, "worker": worker.address})
    _freeze_once()
    return lint_target(target, settings, lint=lint, known=known, record=record)


_frozen = False


def _freeze_once() -> None:
    """Keep what the worker process holds before its first lint (distributed, tornado) out of
    the cyclic collector's full collections: a Dask worker's heap is larger than a ``--jobs``
    process's, and every full collection during a lint walks all of it (``gc.freeze`` is for
    such long-lived heaps). The ROS 1 bags, which make the most garbage, measured up to 1.4x
    the CPU time of ``--jobs`` without it, on a machine too loaded to be sure."""
    global _frozen
    if not _frozen:
        _frozen = True
        gc.freeze()


@dataclass(slots=True)
class _Start:
    at: float
    worker: str


class _Run:
    """One fleet run's futures, the start of each task, and the outcomes so far."""

    def __init__(self, client: Any, targets: Sequence[str], settings: Sequence[Settings]) -> None:
        self.client = client
        self.targets = targets
        self.settings = settings
        """Each target's settings, in the order of ``targets``."""
        self.id = uuid.uuid4().hex[:12]
        self.topic = f"fuzzoff-started-{self.id}"
        self.lock = threading.Lock()
        self.started: dict[int, _Start] = {}
        self.outcomes: list[Outcome | None] = [None] * len(targets)

    def on_start(self, event: tuple[float, dict[str, Any]]) -> None:
        msg = event[1]
        with self.lock:
            self.started[int(msg["index"])] = _Start(time.monotonic(), str(msg["worker"]))

    def elapsed(self, index: int) -> float | None:
        with self.lock:
            start = self.started.get(index)
        return None if start is None else time.monotonic() - start.at

    def overdue(self, timeout_s: float) -> list[tuple[int, str]]:
        now = time.monotonic()
        with self.lock:
            return [
                (i, s.worker)
                for i, s in self.started.items()
                if self.outcomes[i] is None and now - s.at > timeout_s
            ]

    def forget_worker(self, worker: str) -> None:
        """Tasks that were on a restarted worker start again elsewhere: their clocks too."""
        with self.lock:
            for i in [i for i, s in self.started.items() if s.worker == worker]:
                del self.started[i]

    def bystander(self, index: int, exc: BaseException) -> bool:
        """Did the task die with workers that were killed by another task? A worker that
        dies takes the tasks queued on it along; the one that killed it had started there."""
        from distributed import KilledWorker

        if not isinstance(exc, KilledWorker):
            return False
        with self.lock:
            start = self.started.get(index)
        return start is None or start.worker != exc.last_worker.address

    def failed(self, index: int, exc: BaseException) -> Outcome:
        """The outcome of a task that raised: its worker died (``KilledWorker``) or fuzzoff
        raised (a bug: the report names the exception)."""
        from distributed import KilledWorker

        after = self.elapsed(index)
        took = "" if after is None else f" after {after:.1f} s"
        if isinstance(exc, KilledWorker):
            what = (
                f"the lint did not finish: the Dask worker process linting it died{took} "
                "(killed, out of memory, or a crash in a reader), and so did the next one "
                "it was given to; the scheduler gave up on it"
            )
            return self._failed(index, what, CRASHED, after)
        what = f"the lint did not finish: fuzzoff failed{took} ({type(exc).__name__}: {exc})"
        return self._failed(index, what, FAILED, after)

    def _failed(self, index: int, what: str, status: str, after: float | None) -> Outcome:
        target = self.targets[index]
        report = failed_report(target, what, self.settings[index])
        return Outcome(target, report, status, seconds=after or 0.0)

    def timed_out(self, index: int, worker: str, timeout_s: float) -> Outcome:
        what = (
            f"the lint did not finish within {timeout_s:g} s (--timeout): stopped by ending "
            f"its Dask worker {worker} (its nanny starts a new one)"
        )
        return self._failed(index, what, TIMED_OUT, timeout_s)


def run_on_cluster(
    client: Any,
    targets: Sequence[str],
    settings: Settings | Sequence[Settings],
    *,
    timeout_s: float = DEFAULT_TIMEOUT_S,
    lint: Lint = lint_file,
    known: Collection[str] = (),
    record: bool = False,
    on_outcome: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    """Lint every target as its own task on ``client``'s cluster, with ``settings`` (one for
    all, or each target's own in the order of ``targets``); the outcomes in the order of
    ``targets``, each handed to ``on_outcome`` as it arrives. Results are gathered in batches
    as they finish; a watchdog thread stops the tasks that run past ``timeout_s``."""
    from distributed import as_completed

    each = [settings] * len(targets) if isinstance(settings, Settings) else list(settings)
    run = _Run(client, targets, each)
    client.subscribe_topic(run.topic, run.on_start)
    known_arg: Any = frozenset(known)
    if known:  # once to every worker, not once per task
        # in a list: scatter sends a collection's items one by one
        [known_arg] = client.scatter([frozenset(known)], broadcast=True, hash=False)
    futures: dict[str, Any] = {}
    tries: dict[int, int] = {}

    def submit(i: int) -> Any:
        tries[i] = tries.get(i, 0) + 1
        key = _key(run, i, tries[i])
        future = client.submit(
            _run, i, targets[i], each[i], run.topic, lint, known_arg, record, key=key, pure=False
        )
        futures[key] = future
        return future

    def done(i: int, outcome: Outcome) -> None:
        with run.lock:
            if run.outcomes[i] is not None:
                return
            run.outcomes[i] = outcome
            if on_outcome is not None:
                on_outcome(outcome)

    results = as_completed(
        [submit(i) for i in range(len(targets))], with_results=True, raise_errors=False
    )
    stop = threading.Event()
    watchdog = threading.Thread(
        target=_watch, args=(run, futures, tries, timeout_s, done, stop), daemon=True
    )
    watchdog.start()
    try:
        for batch in results.batches():
            for future, result in batch:
                i = int(future.key.rsplit("-", 2)[1])
                futures.pop(future.key, None)
                future.release()
                if isinstance(result, Outcome):
                    done(i, result)
                    continue
                exc = _raised(result)
                if run.bystander(i, exc) and tries[i] < BYSTANDER_TRIES:
                    results.add(submit(i))
                else:
                    done(i, run.failed(i, exc))
    finally:
        stop.set()
        watchdog.join()
        client.unsubscribe_topic(run.topic)
        for future in list(futures.values()):
            future.cancel()
    return [o for o in run.outcomes if o is not None]


def _key(run: _Run, index: int, attempt: int) -> str:
    return f"fuzzoff-lint-{run.id}-{index}-{attempt}"


def _raised(result: Any) -> BaseException:
    """What a failed task raised (``as_completed`` gives it as ``(type, value, traceback)``)."""
    if isinstance(result, tuple) and len(result) == 3 and isinstance(result[1], BaseException):
        return result[1]
    return RuntimeError(f"unexpected task result {type(result).__name__}")


def _watch(
    run: _Run,
    futures: dict[str, Any],
    tries: dict[int, int],
    timeout_s: float,
    done: Callable[[int, Outcome], None],
    stop: threading.Event,
) -> None:
    """Every ``WATCH_S``: a task past the timeout is cancelled (its outcome: OFB001) and its
    worker process ended, the only way to stop the thread that runs it."""
    while not stop.wait(WATCH_S):
        for i, worker in run.overdue(timeout_s):
            key = _key(run, i, tries[i])
            if not _still_on(run.client, key, worker):
                run.forget_worker(worker)  # it died and the task is queued again
                continue
            # the outcome first: the cancelled task may come back as cancelled, not as this
            done(i, run.timed_out(i, worker, timeout_s))
            future = futures.pop(key, None)
            if future is not None:
                future.cancel()
            _end_worker(run.client, worker)
            run.forget_worker(worker)


def _end_worker(client: Any, worker: str) -> None:
    """End the worker's process at once; its nanny starts a new one. A graceful restart
    (``Client.restart_workers``) waits for the worker to close, and a worker whose thread
    never returns cannot: Python joins its executor's threads at exit."""
    with contextlib.suppress(Exception):  # the worker is gone before it can answer
        client.run(_exit, workers=[worker], wait=False)


async def _exit() -> None:
    """Run on the worker's event loop (``Client.run`` sends only a coroutine without waiting
    for its answer), not in its busy thread pool."""
    os._exit(EXIT_STOPPED)


def _still_on(client: Any, key: str, worker: str) -> bool:
    processing: dict[str, Any] = client.processing(workers=[worker])
    return key in processing.get(worker, ())
