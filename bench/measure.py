"""One measured child process: wall time, CPU time and that child's own peak RSS.

Every benchmark runs each side (fuzzoff, the bare library) as its own process, so imports and
start-up count for both. The command is started from a small wrapper process, not from the
benchmark itself: Linux carries a parent's peak RSS over to a child at exec (the old mm's high
water mark is kept in the child's rusage), so spawning straight from a benchmark process that
holds generated data would put a floor under every figure.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

WRAPPER = """
import json, os, subprocess, sys, time
start = time.perf_counter()
proc = subprocess.Popen(sys.argv[1:], stderr=subprocess.DEVNULL)
_, status, usage = os.wait4(proc.pid, 0)
wall = time.perf_counter() - start
print(json.dumps([wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss]), file=sys.stderr)
"""


@dataclass
class Run:
    wall_s: float
    cpu_s: float
    rss_mb: float
    output: str


def measure(args: list[str], env: dict[str, str] | None = None) -> Run:
    """Run ``args`` from the repository root; stdout captured, the child's stderr discarded."""
    full_env = {**os.environ, "NO_COLOR": "1", "MAVLINK20": "1", **(env or {})}
    with tempfile.TemporaryFile() as out:
        proc = subprocess.run(
            [sys.executable, "-c", WRAPPER, *args],
            stdout=out,
            stderr=subprocess.PIPE,
            cwd=ROOT,
            env=full_env,
            check=False,
        )
        out.seek(0)
        text = out.read().decode(errors="replace")
    wall, cpu, rss_kb = json.loads(proc.stderr.decode().strip().splitlines()[-1])
    return Run(wall, cpu, rss_kb / 1024, text)


def per_message_split(messages: int, bare_s: float, reader_s: float, lint_s: float) -> str:
    """What a 1.3x target leaves a message for fuzzoff's own work, beside what its reader
    (building the events) and its gate model and checks spend now, in microseconds."""
    if messages <= 0:
        return "no messages"
    us = 1e6 / messages
    return (
        f"under 1.3x: {0.3 * bare_s * us:.2f} us a message for all of fuzzoff's work; "
        f"its reader spends {(reader_s - bare_s) * us:.2f}, "
        f"its gate model and checks {(lint_s - reader_s) * us:.2f}"
    )
