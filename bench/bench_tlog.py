"""tlog speed and memory: ``fuzzoff lint`` beside pymavlink alone on the same files (issue 3/10).

Targets: lint at most 1.3x the bare library (pymavlink's ``mavlink_connection`` iterating every
message); on a log where offboard messages are under 10 %, lint faster than that; peak RSS flat
from 100k to 1M messages; ``--jobs 2`` at least 1.8x ``--jobs 1`` over twenty files.

Every measurement is its own process (CPU time and peak RSS of that process from ``os.wait4``,
wall time from outside), so imports and start-up count for both sides. Speed ratios use CPU
time (user + system): on a shared machine wall time mostly measures the neighbours; ``--jobs``
is judged on wall time, and the load average is printed beside it. The data (bench/data/,
git-ignored) are generated on the first run; ``python -m bench tlog`` runs only this benchmark.
"""

from __future__ import annotations

import os
import shutil
import sys
from collections.abc import Callable
from functools import partial
from pathlib import Path

from bench.measure import Run, measure
from bench.tlog_data import generate

REPEATS = {"100k": 3, "1M": 1, "mixed-500k": 3}

DATA = Path(__file__).resolve().parent / "data"
ROOT = DATA.parent.parent

WANTED_TYPES = (
    "HEARTBEAT,SET_MODE,PARAM_VALUE,COMMAND_INT,COMMAND_LONG,COMMAND_ACK,SET_ATTITUDE_TARGET,"
    "SET_POSITION_TARGET_LOCAL_NED,SET_POSITION_TARGET_GLOBAL_INT,AUTOPILOT_VERSION,STATUSTEXT"
)

BARE = """
import os, sys
os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil
log = mavutil.mavlink_connection(sys.argv[1], dialect="common")
types = sys.argv[2].split(",") if len(sys.argv) > 2 else None
n = 0
while log.recv_match(type=types, blocking=False) is not None:
    n += 1
print(n)
"""

READER = """
import sys
from pathlib import Path
from fuzzoff.formats.tlog.reader import TlogSource
source = TlogSource(Path(sys.argv[1]))
with source:
    source.probe()
    print(sum(1 for _ in source.events()))
"""


def lint(paths: list[Path], jobs: int = 1) -> Run:
    return measure(
        [
            sys.executable,
            "-m",
            "fuzzoff.cli",
            "lint",
            *map(str, paths),
            "--format",
            "json",
            "--no-progress",
            "--jobs",
            str(jobs),
        ]
    )


def bare(path: Path, types: str | None = None) -> Run:
    return measure([sys.executable, "-c", BARE, str(path), *([types] if types else [])])


def reader(path: Path) -> Run:
    return measure([sys.executable, "-c", READER, str(path)])


def best_of(methods: dict[str, Callable[[], Run]], repeats: int) -> dict[str, Run]:
    """Round-robin over the methods ``repeats`` times; keep each one's fastest run.

    The machine is shared, so load changes from minute to minute: interleaving gives every
    method the same chances, and the minimum is the least disturbed run.
    """
    best: dict[str, Run] = {}
    for _ in range(repeats):
        for what, fn in methods.items():
            run = fn()
            if what not in best or run.cpu_s < best[what].cpu_s:
                rss = max(run.rss_mb, best.get(what, run).rss_mb)
                best[what] = Run(wall_s=run.wall_s, cpu_s=run.cpu_s, rss_mb=rss, output="")
    return best


def _row(name: str, what: str, messages: int, run: Run) -> None:
    rate = messages / run.cpu_s if run.cpu_s else 0.0
    print(
        f"{name:<12} {what:<26} {run.cpu_s:7.2f} s {run.wall_s:7.2f} s "
        f"{rate:9,.0f} msg/s {run.rss_mb:7.1f} MB"
    )


def main() -> None:
    files = {
        "100k": (generate(DATA / "tlog_100k.tlog", 100_000), 100_000),
        "1M": (generate(DATA / "tlog_1m.tlog", 1_000_000), 1_000_000),
        "mixed-500k": (generate(DATA / "tlog_mixed_500k.tlog", 500_000, 11), 500_000),
    }
    print(f"{'file':<12} {'method':<26} {'CPU':>9} {'wall':>9} {'rate (CPU)':>15} {'peak RSS':>10}")
    results: dict[str, dict[str, Run]] = {}
    for name, (path, messages) in files.items():
        methods: dict[str, Callable[[], Run]] = {
            "pymavlink, every message": partial(bare, path),
            "pymavlink, type filter": partial(bare, path, WANTED_TYPES),
            "fuzzoff tlog reader alone": partial(reader, path),
            "fuzzoff lint": partial(lint, [path]),
        }
        runs = best_of(methods, REPEATS[name])
        results[name] = runs
        size_mb = path.stat().st_size / 1e6
        for what, run in runs.items():
            _row(name, what, messages, run)
        print(f"{'':<12} ({messages:,} messages, {size_mb:.1f} MB, best of {REPEATS[name]})")

    def ratio(name: str, what: str = "fuzzoff lint") -> float:
        runs = results[name]
        return runs[what].cpu_s / runs["pymavlink, every message"].cpu_s

    print()
    print("target                                             measured   ok")
    for name in ("100k", "1M"):
        r = ratio(name)
        print(f"lint / bare library ({name:<4}) <= 1.3x                  {r:7.2f}x   {r <= 1.3}")
    r = ratio("mixed-500k")
    print(f"lint / bare library (offboard < 10 %) < 1.0x          {r:7.2f}x   {r < 1.0}")
    for name in files:
        r = ratio(name, "fuzzoff tlog reader alone")
        print(f"  (reader alone, no checks, {name}: {r:.2f}x the bare library)")
    rss_small = results["100k"]["fuzzoff lint"].rss_mb
    rss_big = results["1M"]["fuzzoff lint"].rss_mb
    growth = rss_big / rss_small
    print(
        f"lint peak RSS 1M / 100k flat (<= 1.1x)              {growth:7.2f}x   {growth <= 1.1}"
        f"   ({rss_small:.0f} -> {rss_big:.0f} MB)"
    )
    bare_growth = (
        results["1M"]["pymavlink, every message"].rss_mb
        / results["100k"]["pymavlink, every message"].rss_mb
    )
    print(f"  (pymavlink alone: {bare_growth:.2f}x)")

    one = generate(DATA / "tlog_25k.tlog", 25_000)
    folder = DATA / "twenty"
    folder.mkdir(exist_ok=True)
    copies = []
    for i in range(20):
        copy = folder / f"flight_{i:02d}.tlog"
        if not copy.exists():
            shutil.copyfile(one, copy)
        copies.append(copy)
    load_before = os.getloadavg()[0]
    # wall time is what --jobs buys; best of 3, alternating, as for the other rows
    j1_wall, j2_wall = [], []
    for _ in range(3):
        j1_wall.append(lint(copies, jobs=1).wall_s)
        j2_wall.append(lint(copies, jobs=2).wall_s)
    j1 = Run(wall_s=min(j1_wall), cpu_s=0.0, rss_mb=0.0, output="")
    j2 = Run(wall_s=min(j2_wall), cpu_s=0.0, rss_mb=0.0, output="")
    speedup = j1.wall_s / j2.wall_s
    print(
        f"--jobs 2 vs --jobs 1, 20 files x 25k >= 1.8x          {speedup:7.2f}x   "
        f"{speedup >= 1.8}   ({j1.wall_s:.1f} s -> {j2.wall_s:.1f} s, {os.cpu_count()} CPUs, "
        f"load average {load_before:.1f})"
    )


if __name__ == "__main__":
    main()
