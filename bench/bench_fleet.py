"""Fleet throughput (issues 22, 31): 1,000 small recordings in a mix of formats, linted with
``--jobs 1``, ``--jobs 2``, and on Dask (``--scheduler local``, several recordings to a task)
with one and two workers, in the same run: ``FUZZOFF_BENCH_ROUNDS`` rounds (default 3) of the
four, each Dask run beside its ``--jobs`` run, every ratio the median of the rounds' ratios.

Targets: Dask at most 10 % slower than ``--jobs`` at the same worker count; Dask from one to
two workers at least 1.8x. Each configuration is one ``fuzzoff lint`` process over the same
folder, start-up (and the LocalCluster's) included, as a user runs it; figures are wall time,
since parallel speed is the point, with the load average printed beside them (the machine is
shared), and the CPU time of all the command's processes beside it, which the neighbours
disturb less. Every configuration must give the same JSON report. The recordings (bench/data/fleet,
git-ignored) are written once by the benchmarks' generators, which go through fuzzoff's
writers: ULogs and tlogs where offboard messages are a small share of the log, as fleets have
them, and MCAP, ROS 2 (sqlite3) and ROS 1 bags of PX4 or MAVROS topics.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from statistics import median

from bench import ros2_data, rosbag1_data, tlog_data, ulog_data
from bench.measure import Run, measure

DATA = Path(__file__).resolve().parent / "data" / "fleet"
COUNT = 1000
MIX: tuple[tuple[str, int], ...] = (
    ("tlog", 300),
    ("ulog", 250),
    ("mcap", 200),
    ("rosbag1", 150),
    ("rosbag2", 100),
)
"""Recordings per format (out of ``COUNT``)."""

OVERHEAD_TARGET = 1.10
SCALING_TARGET = 1.8


def _messages(i: int) -> int:
    """1,500 to 4,000 messages: every recording has its own size and content."""
    return 1500 + (i * 37) % 2500


def _writers() -> dict[str, Callable[[Path, int], Path]]:
    return {
        "tlog": lambda p, n: tlog_data.generate(p, n, fillers_per_setpoint=3),
        "ulog": lambda p, n: ulog_data.generate(p, n, mixed=True),
        "mcap": lambda p, n: ros2_data.generate(p, "mcap", n),
        "rosbag1": lambda p, n: rosbag1_data.generate(p, n),
        "rosbag2": lambda p, n: ros2_data.generate(p, "rosbag2-sqlite3", n),
    }


SUFFIX = {"tlog": ".tlog", "ulog": ".ulg", "mcap": ".mcap", "rosbag1": ".bag", "rosbag2": ""}


def generate() -> Path:
    """Write the recordings once (a ``.done`` file says the set is complete)."""
    done = DATA / ".done"
    if done.exists():
        return DATA
    writers = _writers()
    i = 0
    for fmt, count in MIX:
        for k in range(count):
            path = DATA / fmt / f"flight_{k:04d}{SUFFIX[fmt]}"
            if not path.exists():
                writers[fmt](path, _messages(i))
            i += 1
    for marker in DATA.rglob("*.done"):  # the ROS 2 generator's own markers
        marker.unlink()
    done.touch()
    return DATA


def _lint(extra: list[str]) -> tuple[Run, str]:
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        args = ["-m", "fuzzoff.cli", "lint", str(DATA), "--format", "json", "-o", out.name]
        run = measure([sys.executable, *args, "--no-progress", *extra])
        return run, Path(out.name).read_text()


CONFIGS = {
    "--jobs 1": ["--jobs", "1"],
    "dask, 1 worker": ["--scheduler", "local", "--jobs", "1"],
    "--jobs 2": ["--jobs", "2"],
    "dask, 2 workers": ["--scheduler", "local", "--jobs", "2"],
}
"""In the order each round runs them: each Dask run right after the ``--jobs`` run it is
compared with, so the two see the same neighbours."""
ROUNDS = int(os.environ.get("FUZZOFF_BENCH_ROUNDS", "3"))
"""Rounds of the four: every ratio is the median of its rounds' ratios (paired)."""


def _tasks(workers: int) -> int:
    """How many Dask tasks the recordings make (``fuzzoff.fleet.batches``)."""
    from fuzzoff.fleet.batches import plan, recording_bytes
    from fuzzoff.formats import find_recordings

    recordings = [str(p) for p in find_recordings(DATA)]
    return len(plan([recording_bytes(r) for r in recordings], workers))


def main() -> None:
    print(f"generating {COUNT} recordings in {DATA} (once)", flush=True)
    generate()
    print(
        f"  Dask tasks: {_tasks(1)} with one worker, {_tasks(2)} with two "
        f"(one per recording before issue 31: {COUNT})",
        flush=True,
    )
    wall: dict[str, list[float]] = {name: [] for name in CONFIGS}
    cpu: dict[str, list[float]] = {name: [] for name in CONFIGS}
    reports: set[str] = set()
    loads: list[float] = []
    for round_ in range(1, ROUNDS + 1):
        for name, extra in CONFIGS.items():
            before = os.getloadavg()[0]
            run, report = _lint(extra)
            reports.add(report)
            after = os.getloadavg()[0]
            loads += [before, after]
            wall[name].append(run.wall_s)
            cpu[name].append(run.cpu_s)
            print(
                f"  round {round_} {name:<16} {run.wall_s:7.2f} s wall  "
                f"{COUNT / run.wall_s:6.1f} recordings/s  cpu {run.cpu_s:6.1f} s "
                f"(all its processes)  load {before:.2f} before, {after:.2f} after",
                flush=True,
            )
    print(f"  load average over the runs: {min(loads):.2f} to {max(loads):.2f} (2 cores)")
    print(f"  same JSON report from every run: {'yes' if len(reports) == 1 else 'NO'}")
    for name in CONFIGS:
        print(
            f"  median {name:<16} {median(wall[name]):7.2f} s wall  "
            f"{COUNT / median(wall[name]):6.1f} recordings/s  cpu {median(cpu[name]):6.1f} s"
        )
    pairs = ((1, "--jobs 1", "dask, 1 worker"), (2, "--jobs 2", "dask, 2 workers"))
    for workers, jobs, dask in pairs:
        ratio = _paired(wall[dask], wall[jobs])
        verdict = "met" if ratio <= OVERHEAD_TARGET else "MISSED"
        print(
            f"  Dask beside --jobs at {workers} worker{'s' if workers > 1 else ''}: "
            f"{ratio:.2f}x the time (target <= {OVERHEAD_TARGET:.2f}x): {verdict}; "
            f"{_paired(cpu[dask], cpu[jobs]):.2f}x the CPU time "
            f"(rounds: {_each(wall[dask], wall[jobs])})"
        )
    for label, one, two in (
        ("Dask", "dask, 1 worker", "dask, 2 workers"),
        ("--jobs", "--jobs 1", "--jobs 2"),
    ):
        speedup = _paired(wall[one], wall[two])
        verdict = "met" if speedup >= SCALING_TARGET else "MISSED"
        target = f" (target >= {SCALING_TARGET}x): {verdict}" if label == "Dask" else ""
        print(
            f"  {label} from 1 to 2 workers: {speedup:.2f}x{target} (rounds: "
            f"{_each(wall[one], wall[two])})"
        )
    extra = _paired_diff(cpu["dask, 1 worker"], cpu["--jobs 1"])
    print(
        f"  Dask's own CPU time beside --jobs at 1 worker: {extra:.1f} s, "
        f"{extra / COUNT * 1000:.1f} ms a recording (start-up included)"
    )


def _paired(a: list[float], b: list[float]) -> float:
    """The median of the rounds' ratios ``a / b``."""
    return median(x / y for x, y in zip(a, b, strict=True))


def _paired_diff(a: list[float], b: list[float]) -> float:
    return median(x - y for x, y in zip(a, b, strict=True))


def _each(a: list[float], b: list[float]) -> str:
    return ", ".join(f"{x / y:.2f}" for x, y in zip(a, b, strict=True))
