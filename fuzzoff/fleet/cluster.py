"""Recordings as Dask tasks: several small recordings per task (sized by their bytes,
``batches``), results as they finish, no recording able to end the run.

A worker process that dies while linting (a crash in a reader's C code, the kernel's OOM
killer) is restarted by its nanny and the scheduler tries the task again elsewhere; when it
has killed ``allowed-failures`` + 1 workers the scheduler gives up on it (``KilledWorker``).
A task of several recordings that fails so is run again one recording per task, to find
which: the one that kills its workers alone becomes that recording's OFB001. ``--timeout`` is
per recording: the clock runs from the recording's own start, not from the task's submission
(a long queue times nothing out) nor from its task's start (a recording late in a task has the
whole timeout too). A task announces its start once (``Worker.log_event``); the worker keeps
which recording each of its tasks is on and since when (``_ON``), and the client asks for it
only about a task that started more than the timeout ago (announcing every recording cost a
fleet of small recordings 1.3 ms of CPU each, issue 31). A recording past the timeout is
stopped the only way a thread can be: its task is cancelled and its worker process ended, and
the worker's nanny starts a new one; the task's other recordings go again as a task of their
own.
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
from typing import Any

from fuzzoff.config import ConfigError, Settings
from fuzzoff.engine import lint_file
from fuzzoff.fleet import require
from fuzzoff.fleet.batches import plan, recording_bytes
from fuzzoff.fleet.task import CRASHED, FAILED, TIMED_OUT, Lint, Outcome, failed_report, lint_target
from fuzzoff.lean_dataclass import dataclass

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
        # psutil's look at the machine's CPU, memory, network and disks, every 500 ms in
        # the scheduler and every worker: a dashboard's plots, which a lint run does not show
        "distributed.admin.system-monitor.interval": "10s",
    }
    with dask.config.set(local):
        return LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # any free port: no warning when 8787 is taken
            silence_logs=logging.ERROR,
            # no memory management: a lint's memory is flat, there is nothing to spill, and
            # the monitors behind it (every 100 ms in each worker and its nanny) woke the
            # worker's event loop into the lint's thread some 200 times a second (issue 31).
            # A worker that runs out of memory is still ended by the kernel, restarted by its
            # nanny, and its recording reported as OFB001.
            memory_limit=0,
        )


_ON: dict[str, tuple[int, float]] = {}
"""In a worker process: each running task's recording (its position in the task) and when it
started (``time.monotonic``), by task key."""


def _run(
    key: str,
    targets: Sequence[str],
    settings: Sequence[Settings],
    topic: str,
    lint: Lint,
    known: Collection[str],
    record: bool,
) -> list[Outcome]:
    """The task: lint its recordings in turn. Its start is announced (the client's clock of
    the task, and where it runs); which recording it is on and since when stays here, in
    ``_ON``, for ``_on_now``."""
    from distributed import get_worker

    worker = get_worker()
    _freeze_once()
    worker.log_event(topic, {"key": key, "worker": worker.address})
    outcomes = []
    try:
        for position, (target, each) in enumerate(zip(targets, settings, strict=True)):
            _ON[key] = (position, time.monotonic())
            outcomes.append(lint_target(target, each, lint=lint, known=known, record=record))
    finally:
        _ON.pop(key, None)
    return outcomes


async def _on_now(key: str) -> tuple[int, float] | None:
    """Run on the worker's event loop (its lint thread may be busy): the recording task ``key``
    is on (its position) and how long ago it started; None once the task is over."""
    on = _ON.get(key)
    return None if on is None else (on[0], time.monotonic() - on[1])


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
class _Task:
    """One Dask task: the recordings it lints in turn (one, or a batch)."""

    indices: tuple[int, ...]
    tries: int = 1
    """Submissions of these recordings together (a task that died with workers another task
    killed is submitted again as it was)."""


@dataclass(slots=True)
class _Start:
    """A task's start, as announced: when (the client's clock), and on which worker."""

    at: float
    worker: str


class _Run:
    """One fleet run's tasks, the recording each is on, and the outcomes so far.

    ``lock`` guards ``pending``: whoever takes a task out of it (its result arriving, or the
    watchdog stopping it) decides what becomes of its recordings, once."""

    def __init__(
        self,
        client: Any,
        targets: Sequence[str],
        settings: Sequence[Settings],
        submit: Callable[[_Task], None],
    ) -> None:
        self.client = client
        self.targets = targets
        self.settings = settings
        """Each target's settings, in the order of ``targets``."""
        self.submit = submit
        self.id = uuid.uuid4().hex[:12]
        self.topic = f"fuzzoff-started-{self.id}"
        self.lock = threading.RLock()
        self.pending: dict[str, tuple[_Task, Any]] = {}
        """Each task not yet resolved, with its future, by key."""
        self.started: dict[str, _Start] = {}
        self.outcomes: list[Outcome | None] = [None] * len(targets)
        self.on_outcome: Callable[[Outcome], None] | None = None
        self._serial = 0

    def key(self) -> str:
        with self.lock:
            self._serial += 1
            return f"fuzzoff-lint-{self.id}-{self._serial}"

    def on_start(self, event: tuple[float, dict[str, Any]]) -> None:
        msg = event[1]
        start = _Start(time.monotonic(), str(msg["worker"]))
        with self.lock:
            self.started[str(msg["key"])] = start

    def take(self, key: str) -> _Task | None:
        """The task, now resolved by the caller; None when it was resolved already."""
        with self.lock:
            taken = self.pending.pop(key, None)
        return None if taken is None else taken[0]

    def done(self, index: int, outcome: Outcome) -> None:
        with self.lock:
            if self.outcomes[index] is not None:
                return
            self.outcomes[index] = outcome
            if self.on_outcome is not None:
                self.on_outcome(outcome)

    def elapsed(self, key: str) -> float | None:
        with self.lock:
            start = self.started.get(key)
        return None if start is None else time.monotonic() - start.at

    def overdue(self, timeout_s: float) -> list[tuple[str, _Start]]:
        """The tasks that started more than ``timeout_s`` ago: their current recording may
        have too (``_watch`` asks)."""
        now = time.monotonic()
        with self.lock:
            return [
                (key, start)
                for key, start in self.started.items()
                if key in self.pending and now - start.at > timeout_s
            ]

    def forget_worker(self, worker: str) -> None:
        """Tasks that were on a restarted worker start again elsewhere: their clocks too."""
        with self.lock:
            for key in [k for k, s in self.started.items() if s.worker == worker]:
                del self.started[key]

    def bystander(self, key: str, exc: BaseException) -> bool:
        """Did the task die with workers that were killed by another task? A worker that
        dies takes the tasks queued on it along; the one that killed it had started there."""
        from distributed import KilledWorker

        if not isinstance(exc, KilledWorker):
            return False
        with self.lock:
            start = self.started.get(key)
        return start is None or start.worker != exc.last_worker.address

    def failed(self, key: str, index: int, exc: BaseException) -> Outcome:
        """The outcome of a task of one recording that raised: its worker died
        (``KilledWorker``) or fuzzoff raised (a bug: the report names the exception)."""
        from distributed import KilledWorker

        after = self.elapsed(key)
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

    def resolve(self, key: str, task: _Task, result: Any) -> None:
        """What a finished task's result means for its recordings: their outcomes; or, where
        it raised, the same task again (it died with a worker another task killed), each of
        its recordings as a task of its own (to find which one failed it), or the outcome of
        its one recording (``crashed``, ``failed``)."""
        if isinstance(result, list):
            for index, outcome in zip(task.indices, result, strict=True):
                self.done(index, outcome)
            return
        exc = _raised(result)
        if self.bystander(key, exc) and task.tries < BYSTANDER_TRIES:
            self.submit(_Task(task.indices, task.tries + 1))
        elif len(task.indices) > 1:
            for index in task.indices:
                self.submit(_Task((index,)))
        else:
            self.done(task.indices[0], self.failed(key, task.indices[0], exc))

    def stop(self, key: str, start: _Start, position: int, timeout_s: float) -> Any:
        """Stop a task whose recording at ``position`` ran past the timeout: that recording is
        ``timed out``, the task's other recordings go again as a task of their own. The
        stopped task's future, or None when it was resolved already."""
        with self.lock:
            taken = self.pending.pop(key, None)
            if taken is None:
                return None
            task, future = taken
            index = task.indices[position]
            what = (
                f"the lint did not finish within {timeout_s:g} s (--timeout): stopped by ending "
                f"its Dask worker {start.worker} (its nanny starts a new one)"
            )
            self.done(index, self._failed(index, what, TIMED_OUT, timeout_s))
            rest = tuple(i for i in task.indices if self.outcomes[i] is None)
            if rest:
                self.submit(_Task(rest))
        return future


def workers_of(client: Any) -> int:
    """The threads the cluster's workers run tasks in (at least one)."""
    try:
        threads: dict[str, int] = client.nthreads()
    except Exception:  # a scheduler that cannot say: plan for one
        return 1
    return max(1, sum(threads.values()))


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
    tasks: Sequence[tuple[int, ...]] | None = None,
) -> list[Outcome]:
    """Lint every target on ``client``'s cluster, with ``settings`` (one for all, or each
    target's own in the order of ``targets``); the outcomes in the order of ``targets``,
    each handed to ``on_outcome`` as it arrives. ``tasks`` groups the targets' indices into
    tasks (default: by their bytes, ``batches.plan``). Results are gathered in batches as
    they finish; a watchdog thread stops the recordings that run past ``timeout_s``."""
    from distributed import as_completed

    each = [settings] * len(targets) if isinstance(settings, Settings) else list(settings)
    if tasks is None:
        tasks = plan([recording_bytes(t) for t in targets], workers_of(client))
    results = as_completed([], loop=client.loop, with_results=True, raise_errors=False)
    known_arg: Any = frozenset(known)

    def submit(task: _Task) -> None:
        key = run.key()
        future = client.submit(
            _run,
            key,
            [targets[i] for i in task.indices],
            [each[i] for i in task.indices],
            run.topic,
            lint,
            known_arg,
            record,
            key=key,
            pure=False,
        )
        with run.lock:
            run.pending[key] = (task, future)
        results.add(future)

    run = _Run(client, targets, each, submit)
    run.on_outcome = on_outcome
    client.subscribe_topic(run.topic, run.on_start)
    if known:  # once to every worker, not once per task
        # in a list: scatter sends a collection's items one by one
        [known_arg] = client.scatter([frozenset(known)], broadcast=True, hash=False)
    for indices in tasks:
        submit(_Task(tuple(indices)))
    stop = threading.Event()
    watchdog = threading.Thread(target=_watch, args=(run, timeout_s, stop), daemon=True)
    watchdog.start()
    try:
        for batch in results.batches():
            for future, result in batch:
                task = run.take(future.key)
                future.release()
                if task is not None:
                    run.resolve(future.key, task, result)
    finally:
        stop.set()
        watchdog.join()
        client.unsubscribe_topic(run.topic)
        with run.lock:
            left = [future for _, future in run.pending.values()]
        for future in left:
            future.cancel()
    return [o for o in run.outcomes if o is not None]


def _raised(result: Any) -> BaseException:
    """What a failed task raised (``as_completed`` gives it as ``(type, value, traceback)``)."""
    if isinstance(result, tuple) and len(result) == 3 and isinstance(result[1], BaseException):
        return result[1]
    return RuntimeError(f"unexpected task result {type(result).__name__}")


def _watch(run: _Run, timeout_s: float, stop: threading.Event) -> None:
    """Every ``WATCH_S``: a recording past the timeout is ``timed out`` (OFB001), its task
    cancelled and its worker process ended, the only way to stop the thread that runs it."""
    while not stop.wait(WATCH_S):
        for key, start in run.overdue(timeout_s):
            if not _still_on(run.client, key, start.worker):
                run.forget_worker(start.worker)  # it died and the task is queued again
                continue
            on = _recording_on(run.client, key, start.worker)
            if on is None or on[1] <= timeout_s:
                continue  # over, or on a recording that started less than the timeout ago
            # the outcome first: the cancelled task may come back as cancelled, not as this
            future = run.stop(key, start, on[0], timeout_s)
            if future is not None:
                future.cancel()
            _end_worker(run.client, start.worker)
            run.forget_worker(start.worker)


def _recording_on(client: Any, key: str, worker: str) -> tuple[int, float] | None:
    """``_on_now`` on the worker: (position, seconds since that recording started), or None
    (the task is over, or the worker is gone). A worker whose event loop cannot answer could
    not be ended by ``_end_worker`` either: the question waits for it, as Dask's own would."""
    try:
        answers: dict[str, Any] = client.run(_on_now, key, workers=[worker])
    except Exception:  # the worker left before it answered: the scheduler retries the task
        return None
    answer = answers.get(worker)
    return None if answer is None else (int(answer[0]), float(answer[1]))


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
