"""ULog speed and memory: ``fuzzoff lint`` beside pyulog alone on the same files (issue 3/10).

Targets: lint at most 1.3x the bare library's time on the same file (pyulog ``ULog(path)``
loading everything); on a log where offboard topics are under 10 % of the messages, lint faster
than pyulog loading everything; on a real-shaped ten-minute log (a real SITL flight of the corpus
repeated, ``bench/ulog_real_data.py``), lint at most pyulog's full load (issue 31). Also shown:
pyulog with fuzzoff's filter list, and fuzzoff's
ULog reader alone (load + every event, no checks), which is the part this format adds.

Every measurement is its own process (wall time from outside, CPU time and peak RSS from
``os.wait4``), so imports and start-up count for both sides; best of three where a run takes
under 10 s (the real log: medians of paired rounds). The data (bench/data/,
git-ignored) are generated on the first run; ``python -m bench ulog`` runs only this one,
``BENCH_ULOG=real python -m bench ulog`` only the real-shaped log.
"""

from __future__ import annotations

import os
import statistics
import sys
from pathlib import Path

from bench.measure import Run, per_message_split
from bench.measure import measure as run_measured
from bench.ulog_data import generate
from bench.ulog_real_data import generate_real
from fuzzoff.formats.ulog.reader import LOADED_TOPICS

DATA = Path(__file__).resolve().parent / "data"
ROOT = DATA.parent.parent

BARE = """
import sys
from pyulog import ULog
topics = sys.argv[2].split(",") if len(sys.argv) > 2 else None
ulog = ULog(sys.argv[1], message_name_filter_list=topics)
print(sum(len(d.data["timestamp"]) for d in ulog.data_list))
"""

READER = """
import os
import statistics
import sys
from pathlib import Path
from fuzzoff.formats.ulog.reader import UlogSource
source = UlogSource(Path(sys.argv[1]))
with source:
    source.probe()
    print(sum(1 for _ in source.events()))
"""


COLUMNS = """
import sys
import numpy as np
from pyulog import ULog
ulog = ULog(sys.argv[1], message_name_filter_list=sys.argv[2].split(","))
data = {d.name: d.data for d in ulog.data_list}
ocm, trajectory, status = (data[t] for t in ("offboard_control_mode", "trajectory_setpoint",
                                             "vehicle_status"))
t = ocm["timestamp"] * 1e-6
gaps = np.diff(t)
losses = np.flatnonzero(gaps > 0.5)
margins = np.percentile(gaps, [50, 95, 99, 100])
flags = np.stack([v for k, v in ocm.items() if k != "timestamp"], axis=1)
declared = np.argmax(flags != 0, axis=1)
declaration_changes = np.flatnonzero(np.diff(declared))
values = np.stack([v for k, v in trajectory.items() if k != "timestamp"], axis=1)
nan = np.isnan(values)
patterns = np.packbits(nan, axis=1, bitorder="little")
pattern_changes = np.flatnonzero(np.any(np.diff(patterns, axis=0) != 0, axis=1))
unchanged = np.all((values[1:] == values[:-1]) | (nan[1:] & nan[:-1]), axis=1)
mode_changes = np.flatnonzero(np.diff(status["nav_state"]) | np.diff(status["arming_state"]))
sparse_at = np.searchsorted(t, status["timestamp"] * 1e-6)
stamps_back = np.flatnonzero(np.diff(ocm["timestamp"].astype(np.int64)) <= 0)
print(len(t) + len(values) + len(sparse_at))
"""
"""The least a design with no event per message would do on the all-offboard files: pyulog's
load with fuzzoff's filter list, then in numpy the keep-alive gaps and their percentiles, the
declared flag of every keep-alive and where it changes, the NaN pattern of every trajectory
setpoint and where it changes, the unchanged setpoints, the mode changes and where the status
messages fall in the stream. No gate model, no findings, no start-up of fuzzoff: a floor."""


def measure(args: list[str]) -> Run:
    """Best of three (of one for runs over 10 s): the machine is shared, noise only adds."""
    best = _measure_once(args)
    for _ in range(2 if best.wall_s < 10 else 0):
        run = _measure_once(args)
        best = Run(
            min(best.wall_s, run.wall_s),
            min(best.cpu_s, run.cpu_s),
            max(best.rss_mb, run.rss_mb),
            run.output,
        )
    return best


def _measure_once(args: list[str]) -> Run:
    return run_measured(args)


PAIRED_RUNS = 5
"""Rounds of the paired real-log measurement (pyulog's full load, then the lint, each round)."""


def paired(path: Path) -> tuple[Run, Run, float, float]:
    """pyulog's full load and the lint, one after the other, ``PAIRED_RUNS`` times: the median
    of each side, and the medians of the per-round ratios (wall, CPU). A shared machine's load
    moves both sides of a round alike."""
    rounds = [
        (_measure_once(_bare_args(path)), _measure_once(_lint_args(path)))
        for _ in range(PAIRED_RUNS)
    ]

    def median_run(runs: list[Run]) -> Run:
        return Run(
            statistics.median(r.wall_s for r in runs),
            statistics.median(r.cpu_s for r in runs),
            statistics.median(r.rss_mb for r in runs),
            runs[-1].output,
        )

    bare_runs = [b for b, _ in rounds]
    lint_runs = [lint for _, lint in rounds]
    wall = statistics.median(lint.wall_s / b.wall_s for b, lint in rounds)
    cpu = statistics.median(lint.cpu_s / b.cpu_s for b, lint in rounds)
    return median_run(bare_runs), median_run(lint_runs), wall, cpu


def columns(path: Path) -> Run:
    return measure([sys.executable, "-c", COLUMNS, str(path), ",".join(LOADED_TOPICS)])


def _lint_args(path: Path) -> list[str]:
    return [
        sys.executable,
        "-m",
        "fuzzoff.cli",
        "lint",
        str(path),
        "--format",
        "json",
        "--no-progress",
    ]


def _bare_args(path: Path, topics: tuple[str, ...] | None = None) -> list[str]:
    extra = [",".join(topics)] if topics else []
    return [sys.executable, "-c", BARE, str(path), *extra]


def lint(path: Path) -> Run:
    return measure(_lint_args(path))


def bare(path: Path, topics: tuple[str, ...] | None = None) -> Run:
    return measure(_bare_args(path, topics))


def reader(path: Path) -> Run:
    return measure([sys.executable, "-c", READER, str(path)])


def _row(name: str, what: str, messages: int, run: Run) -> None:
    rate = messages / run.wall_s if run.wall_s else 0.0
    print(
        f"{name:<12} {what:<30} {run.wall_s:8.2f} s {run.cpu_s:8.2f} s "
        f"{rate:11,.0f} msg/s {run.rss_mb:8.1f} MB"
    )


def main() -> None:
    only = os.environ.get("BENCH_ULOG", "")
    if only == "real":
        real_only()
        return
    files = {
        "100k": generate(DATA / "ulog_100k.ulg", 100_000),
        "1M": generate(DATA / "ulog_1m.ulg", 1_000_000),
        "mixed-1M": generate(DATA / "ulog_mixed_1m.ulg", 1_000_000, mixed=True),  # default profile
        "real-10min": generate_real(DATA / "ulog_real_10min.ulg"),  # a real SITL flight, repeated
    }
    header = f"{'file':<12} {'method':<30} {'wall':>10} {'cpu':>10} {'rate (wall)':>17}"
    print(f"{header} {'peak RSS':>11}")
    results: dict[str, dict[str, Run]] = {}
    for name, path in files.items():
        runs = {
            "pyulog, everything": bare(path),
            "pyulog, fuzzoff's filter list": bare(path, LOADED_TOPICS),
            "fuzzoff ulog reader alone": reader(path),
            "fuzzoff lint": lint(path),
        }
        if name in ("100k", "1M"):
            runs["floor: pyulog + numpy columns"] = columns(path)
        results[name] = runs
        messages = int(runs["pyulog, everything"].output.strip() or 0)
        for what, run in runs.items():
            _row(name, what, messages, run)
        events = runs["fuzzoff ulog reader alone"].output.strip()
        size_mb = path.stat().st_size / 1e6
        print(f"{'':<12} ({messages:,} messages, {events} events, {size_mb:.1f} MB)")

    def ratio(name: str, what: str, against: str = "pyulog, everything") -> tuple[float, float]:
        runs = results[name]
        return (
            runs[what].wall_s / runs[against].wall_s,
            runs[what].cpu_s / runs[against].cpu_s,
        )

    print()
    print("target (wall; cpu in brackets)                           measured           ok")
    for name in ("100k", "1M"):
        wall, cpu = ratio(name, "fuzzoff lint")
        print(
            f"lint / pyulog everything ({name:<4}) <= 1.3x          {wall:7.2f}x ({cpu:5.2f}x)   "
            f"{wall <= 1.3}"
        )
    wall, cpu = ratio("mixed-1M", "fuzzoff lint")
    print(
        f"lint / pyulog everything (offboard < 10 %) < 1.0x   {wall:7.2f}x ({cpu:5.2f}x)   "
        f"{wall < 1.0}"
    )
    _real_verdict(files["real-10min"])
    print(f"  (real-10min: {framing(files['real-10min'])})")
    for name in files:
        wall, cpu = ratio(name, "fuzzoff ulog reader alone")
        fwall, fcpu = ratio(name, "fuzzoff ulog reader alone", "pyulog, fuzzoff's filter list")
        print(
            f"  ({name}: reader alone {wall:.2f}x ({cpu:.2f}x) pyulog everything, "
            f"{fwall:.2f}x ({fcpu:.2f}x) pyulog with the same filter list)"
        )
    for name in ("100k", "1M"):
        runs = results[name]
        split = per_message_split(
            int(runs["pyulog, everything"].output.strip() or 0),
            runs["pyulog, everything"].wall_s,
            runs["fuzzoff ulog reader alone"].wall_s,
            runs["fuzzoff lint"].wall_s,
        )
        wall, cpu = ratio(name, "floor: pyulog + numpy columns")
        print(f"  ({name}: {split};")
        print(f"   a design with no event per message: floor {wall:.2f}x ({cpu:.2f}x))")


def _real_verdict(path: Path) -> None:
    """The issue-31 target on the real-shaped log, from paired rounds (see ``paired``)."""
    bare_run, lint_run, wall, cpu = paired(path)
    # Issue 31 measures CPU time, whole process, as a user meets it. pyulog's process spends
    # CPU beside its main thread (numpy's OpenBLAS threads spin at start; a lint keeps them to
    # one), so its wall time is the other figure to read: shown, not judged.
    print(
        f"lint / pyulog everything (real, 10 min) <= 1.0x CPU  {cpu:7.2f}x CPU ({wall:5.2f}x "
        f"wall)   {cpu <= 1.0}"
    )
    print(
        f"  (real-10min, medians of {PAIRED_RUNS} paired rounds: pyulog everything "
        f"{bare_run.cpu_s:.2f} s CPU, {bare_run.wall_s:.2f} s wall; fuzzoff lint "
        f"{lint_run.cpu_s:.2f} s CPU, {lint_run.wall_s:.2f} s wall)"
    )


def framing(path: Path) -> str:
    """How many of the log's data records the lint hands pyulog (``formats/ulog/framing.py``)."""
    from fuzzoff.formats.ulog.load import load
    from fuzzoff.formats.ulog.reader import _ReadRows

    framed = load(path, LOADED_TOPICS, plan=_ReadRows()).ulog.framed
    if framed is None:
        return "no framing pass (pyulog read every record)"
    return (
        f"framing pass: pyulog decodes {framed.kept:,} of the {framed.records:,} records of "
        f"the data section"
    )


def real_only() -> None:
    """Only the real-shaped ten-minute log (``BENCH_ULOG=real python -m bench ulog``)."""
    path = generate_real(DATA / "ulog_real_10min.ulg")
    reader_run = reader(path)
    filtered = bare(path, LOADED_TOPICS)
    print(f"real-10min: {path.stat().st_size / 1e6:.1f} MB, {reader_run.output.strip()} events")
    print(f"  pyulog, fuzzoff's filter list {filtered.cpu_s:.2f} s CPU (best of 3)")
    print(f"  fuzzoff ulog reader alone     {reader_run.cpu_s:.2f} s CPU (best of 3)")
    print(f"  ({framing(path)})")
    _real_verdict(path)


if __name__ == "__main__":
    main()
