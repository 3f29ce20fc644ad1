"""ROS 1 bag speed and memory: ``fuzzoff lint`` beside rosbags alone on the same files (issue 4/6).

Targets: lint at most 1.3x the bare library decoding the same (MAVROS) topics
(``AnyReader`` + ``deserialize``); on a bag where MAVROS topics are under 10 % of the messages
(IMU, camera), lint at least 3x faster than decoding every message; peak RSS flat from 100k
to 1M messages.

Every measurement is its own process (wall time from outside, peak RSS from ``os.wait4``), so
imports and start-up count for both sides. The data (bench/data/, git-ignored) are generated on
the first run; ``python -m bench rosbag1`` runs only this benchmark.
"""

from __future__ import annotations

import sys
from pathlib import Path

from bench.measure import Run, measure, per_message_split
from bench.rosbag1_data import generate

DATA = Path(__file__).resolve().parent / "data"
ROOT = DATA.parent.parent

MAVROS_TOPICS = "/mavros/setpoint_raw/local,/mavros/state"

BARE = """
import sys
from pathlib import Path
from rosbags.highlevel import AnyReader
topics = set(sys.argv[2].split(",")) if len(sys.argv) > 2 else None
with AnyReader([Path(sys.argv[1])]) as reader:
    conns = [c for c in reader.connections if topics is None or c.topic in topics]
    n = 0
    for conn, _t, raw in reader.messages(connections=conns):
        reader.deserialize(raw, conn.msgtype)
        n += 1
print(n)
"""

READER = """
import sys
from pathlib import Path
from fuzzoff.formats.rosbag1.reader import Rosbag1Source
source = Rosbag1Source(Path(sys.argv[1]))
with source:
    source.probe()
    print(sum(1 for _ in source.events()))
"""


def lint(path: Path) -> Run:
    return measure(
        [
            sys.executable,
            "-m",
            "fuzzoff.cli",
            "lint",
            str(path),
            "--format",
            "json",
            "--no-progress",
        ]
    )


def bare(path: Path, topics: str | None = None) -> Run:
    return measure([sys.executable, "-c", BARE, str(path), *([topics] if topics else [])])


def reader(path: Path) -> Run:
    return measure([sys.executable, "-c", READER, str(path)])


def _row(name: str, what: str, messages: int, run: Run) -> None:
    rate = messages / run.wall_s if run.wall_s else 0.0
    print(
        f"{name:<11} {what:<30} {run.wall_s:7.2f} s {run.cpu_s:7.2f} s "
        f"{rate:10,.0f} msg/s {run.rss_mb:7.1f} MB"
    )


def main() -> None:
    files = {
        "100k": (generate(DATA / "rosbag1_100k.bag", 100_000), 100_000),
        "1M": (generate(DATA / "rosbag1_1m.bag", 1_000_000), 1_000_000),
        "mixed-300k": (
            generate(DATA / "rosbag1_mixed_9pct_300k.bag", 300_000, mixed=True),
            300_000,
        ),
    }
    head = f"{'file':<11} {'method':<30} {'wall':>9} {'CPU':>9}"
    print(f"{head} {'rate (wall)':>16} {'peak RSS':>10}")
    results: dict[str, dict[str, Run]] = {}
    for name, (path, messages) in files.items():
        runs = {
            "rosbags, every message": bare(path),
            "rosbags, MAVROS topics": bare(path, MAVROS_TOPICS),
            "fuzzoff rosbag1 reader alone": reader(path),
            "fuzzoff lint": lint(path),
        }
        results[name] = runs
        for what, run in runs.items():
            _row(name, what, messages, run)
        size_mb = path.stat().st_size / 1e6
        print(f"{'':<11} ({messages:,} messages, {size_mb:.1f} MB)")

    def ratio(name: str, what: str, base: str) -> float:
        runs = results[name]
        return runs[what].cpu_s / runs[base].cpu_s

    print()
    print("target (CPU time; the machine is shared)                measured   ok")
    for name in ("100k", "1M"):
        r = ratio(name, "fuzzoff lint", "rosbags, MAVROS topics")
        print(f"lint / rosbags same topics ({name:<4}) <= 1.3x              {r:7.2f}x   {r <= 1.3}")
        r = ratio(name, "fuzzoff rosbag1 reader alone", "rosbags, MAVROS topics")
        print(f"  (reader alone, no checks: {r:.2f}x)")
        runs = results[name]
        split = per_message_split(
            files[name][1],
            runs["rosbags, MAVROS topics"].cpu_s,
            runs["fuzzoff rosbag1 reader alone"].cpu_s,
            runs["fuzzoff lint"].cpu_s,
        )
        print(f"  ({split})")
    r = 1 / ratio("mixed-300k", "fuzzoff lint", "rosbags, every message")
    print(f"lint faster than decoding everything (mixed) >= 3x       {r:7.2f}x   {r >= 3.0}")
    startup = lint(ROOT / "corpora" / "rosbag1" / "offboard_good.bag").cpu_s
    mixed = results["mixed-300k"]
    r = mixed["rosbags, every message"].cpu_s / mixed["fuzzoff rosbag1 reader alone"].cpu_s
    print(f"  (reader alone vs decoding everything: {r:.2f}x faster; lint start-up {startup:.2f} s")
    print("   CPU on a 400-message bag, so the checks and start-up are the rest)")
    small = results["100k"]["fuzzoff lint"].rss_mb
    big = results["1M"]["fuzzoff lint"].rss_mb
    growth = big / small
    print(
        f"lint peak RSS 1M / 100k flat (<= 1.1x)                   {growth:7.2f}x   "
        f"{growth <= 1.1}   ({small:.0f} -> {big:.0f} MB)"
    )
    bare_growth = (
        results["1M"]["rosbags, MAVROS topics"].rss_mb
        / results["100k"]["rosbags, MAVROS topics"].rss_mb
    )
    print(f"  (rosbags alone: {bare_growth:.2f}x; its index of every message is held in memory)")


if __name__ == "__main__":
    main()
