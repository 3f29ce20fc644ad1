"""ROS 2 speed and memory: ``fuzzoff lint`` beside the bare libraries on the same files (issue 4/8).

Formats: MCAP, rosbag2 sqlite3, rosbag2 mcap; each at 100k and 1M messages (PX4 topics only) and
a mixed recording where the PX4 topics are 9 % of the messages beside IMU and 20 kB camera frames.
Targets: lint at most 1.3x the bare library decoding the same (PX4) topics (rosbags' reader and
CDR deserialiser, the faster library, formats.md 4.5); on the mixed recording, lint at least 3x
faster than decoding every message; peak RSS flat from 100k to 1M messages.

Every measurement is its own process: wall time and CPU time from outside, peak RSS from
``os.wait4``; "work CPU" is the CPU time the child measured after its imports (start-up is
about 0.3 s for fuzzoff, 0.15 s for rosbags alone, which dominates small files), and the
targets are judged on it. Data (bench/data/, git-ignored) are generated on the
first run; ``python -m bench ros2`` runs only this benchmark.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from bench.measure import Run, measure, per_message_split

DATA = Path(__file__).resolve().parent / "data"
ROOT = DATA.parent.parent

BARE_ROSBAGS = """
import sys, time
from pathlib import Path
from rosbags.interfaces import MessageDefinitionFormat
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
px4_only = len(sys.argv) > 2
store = get_typestore(Stores.ROS2_HUMBLE)
start = time.process_time()
with Reader(Path(sys.argv[1])) as reader:
    conns = [c for c in reader.connections if not px4_only or c.msgtype.startswith("px4_msgs/")]
    for c in conns:
        if c.msgtype not in store.fielddefs and c.msgdef.format == MessageDefinitionFormat.MSG:
            store.register(get_types_from_msg(c.msgdef.data, c.msgtype))
    n = 0
    for conn, _t, raw in reader.messages(connections=conns):
        store.deserialize_cdr(raw, conn.msgtype)
        n += 1
print(n, time.process_time() - start)
"""

BARE_MCAP = """
import sys, time
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
start = time.process_time()
with open(sys.argv[1], "rb") as fh:
    reader = make_reader(fh, decoder_factories=[DecoderFactory()])
    topics = [c.topic for c in reader.get_summary().channels.values() if "/fmu/" in c.topic]
    n = sum(1 for _ in reader.iter_decoded_messages(topics=topics, log_time_order=False))
print(n, time.process_time() - start)
"""

READER = """
import sys, time
from pathlib import Path
from fuzzoff.formats import open_source
import fuzzoff.formats.mcap.reader, fuzzoff.formats.rosbag2.reader  # imports are start-up, not work
start = time.process_time()
source = open_source(Path(sys.argv[1]))
with source:
    source.probe()
    n = sum(1 for _ in source.events())
print(n, time.process_time() - start)
"""

LINT = """
import sys, time
from fuzzoff import lint_file
from fuzzoff.checks import load_all
import fuzzoff.formats.mcap.reader, fuzzoff.formats.rosbag2.reader  # imports are start-up, not work
load_all()
start = time.process_time()
report = lint_file(sys.argv[1])
print(len(report.findings), time.process_time() - start)
"""


def work_s(run: Run) -> float:
    """CPU time after start-up and imports, as the child measured it."""
    try:
        return float(run.output.split()[-1])
    except (IndexError, ValueError):
        return float("nan")


def lint(path: Path) -> Run:
    cli = [sys.executable, "-m", "fuzzoff.cli", "lint", str(path), "--format", "json"]
    return measure([*cli, "--no-progress"])


def lint_work(path: Path) -> Run:
    """``lint_file`` timed inside the process (no start-up, no report rendering)."""
    return measure([sys.executable, "-c", LINT, str(path)])


def _row(name: str, what: str, messages: int, run: Run) -> None:
    rate = messages / work_s(run) if work_s(run) else 0.0
    print(
        f"{name:<22} {what:<34} {run.wall_s:7.2f} s {run.cpu_s:7.2f} s {work_s(run):7.2f} s "
        f"{rate:10,.0f} msg/s {run.rss_mb:7.1f} MB",
        flush=True,
    )


GENERATE = """
import sys
from pathlib import Path
from bench.ros2_data import generate
generate(Path(sys.argv[1]), sys.argv[2], int(sys.argv[3]), mixed=sys.argv[4] == "mixed")
"""


def _generate(path: Path, kind: str, messages: int, mixed: bool = False) -> Path:
    """Generate in a child process: the parent stays small, so the children it forks for the
    measurements start small too (a forked child's peak RSS counts the parent's pages)."""
    args = [str(path), kind, str(messages), "mixed" if mixed else "plain"]
    subprocess.run([sys.executable, "-c", GENERATE, *args], cwd=ROOT, check=True)
    return path


def _files(kind: str) -> dict[str, tuple[Path, int]]:
    suffix = ".mcap" if kind == "mcap" else ""
    tag = kind.replace("rosbag2-", "bag-")
    return {
        f"{tag} 100k": (_generate(DATA / f"ros2_{tag}_100k{suffix}", kind, 100_000), 100_000),
        f"{tag} 1M": (_generate(DATA / f"ros2_{tag}_1m{suffix}", kind, 1_000_000), 1_000_000),
        f"{tag} mixed-100k": (
            _generate(DATA / f"ros2_{tag}_mixed_100k{suffix}", kind, 100_000, mixed=True),
            100_000,
        ),
    }


def _size_mb(path: Path) -> float:
    if path.is_dir():
        return sum(p.stat().st_size for p in path.iterdir()) / 1e6
    return path.stat().st_size / 1e6


def main() -> None:
    head = f"{'file':<22} {'method':<34} {'wall':>9} {'CPU':>9} {'work CPU':>9}"
    print(f"{head} {'rate (work)':>16} {'peak RSS':>10}")
    summary: list[str] = []
    for kind in ("mcap", "rosbag2-sqlite3", "rosbag2-mcap"):
        results: dict[str, dict[str, Run]] = {}
        for name, (path, messages) in _files(kind).items():
            bare = [sys.executable, "-c", BARE_ROSBAGS, str(path)]
            runs = {
                "rosbags, every message": measure(bare),
                "rosbags, PX4 topics": measure([*bare, "px4"]),
            }
            if kind == "mcap":
                runs["mcap + mcap_ros2, PX4 topics"] = measure(
                    [sys.executable, "-c", BARE_MCAP, str(path)]
                )
            runs["fuzzoff reader alone"] = measure([sys.executable, "-c", READER, str(path)])
            runs["fuzzoff lint (CLI)"] = lint(path)
            runs["fuzzoff lint"] = lint_work(path)
            results[name] = runs
            for what, run in runs.items():
                _row(name, what, messages, run)
            print(f"{'':<22} ({messages:,} messages, {_size_mb(path):.1f} MB)", flush=True)
        summary += _verdicts(kind, results)
    print()
    print("target (work CPU: after start-up and imports; the machine is shared)  measured  ok")
    for line in summary:
        print(line)


def _verdicts(kind: str, results: dict[str, dict[str, Run]]) -> list[str]:
    tag = kind.replace("rosbag2-", "bag-")
    out = []

    def cpu(name: str, what: str) -> float:
        return work_s(results[f"{tag} {name}"][what])

    for size in ("100k", "1M"):
        r = cpu(size, "fuzzoff lint") / cpu(size, "rosbags, PX4 topics")
        out.append(
            f"{tag:<9} lint / rosbags PX4 topics ({size:<4}) <= 1.3x        {r:8.2f}x   {r <= 1.3}"
        )
        r = cpu(size, "fuzzoff reader alone") / cpu(size, "rosbags, PX4 topics")
        out.append(f"{'':<9}   (reader alone, no checks: {r:.2f}x)")
        bare = results[f"{tag} {size}"]["rosbags, PX4 topics"]
        split = per_message_split(
            int(bare.output.split()[0]),
            work_s(bare),
            cpu(size, "fuzzoff reader alone"),
            cpu(size, "fuzzoff lint"),
        )
        out.append(f"{'':<9}   ({split})")
    r = cpu("mixed-100k", "rosbags, every message") / cpu("mixed-100k", "fuzzoff lint")
    out.append(f"{tag:<9} lint faster than decoding everything (mixed) >= 3x {r:8.2f}x   {r >= 3}")
    small = results[f"{tag} 100k"]["fuzzoff lint (CLI)"].rss_mb
    big = results[f"{tag} 1M"]["fuzzoff lint (CLI)"].rss_mb
    growth = big / small
    out.append(
        f"{tag:<9} lint peak RSS 1M / 100k flat (<= 1.1x)            {growth:8.2f}x   "
        f"{growth <= 1.1}   ({small:.0f} -> {big:.0f} MB)"
    )
    return out


if __name__ == "__main__":
    main()
