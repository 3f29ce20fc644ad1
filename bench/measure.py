"""One measured child process: wall time, CPU time and that child's own peak RSS.

Every benchmark runs each side (fuzzoff, the bare library) as its own process, so imports and
start-up count for both and peak memory is the child's (``os.wait4``), not the maximum over all
children of the benchmark.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


@dataclass
class Run:
    wall_s: float
    cpu_s: float
    rss_mb: float
    output: str


def measure(args: list[str], env: dict[str, str] | None = None) -> Run:
    """Run ``args`` from the repository root with stdout captured and stderr discarded."""
    full_env = {**os.environ, "NO_COLOR": "1", "MAVLINK20": "1", **(env or {})}
    with tempfile.TemporaryFile() as out:
        start = time.perf_counter()
        proc = subprocess.Popen(args, stdout=out, stderr=subprocess.DEVNULL, cwd=ROOT, env=full_env)
        _, _status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        out.seek(0)
        text = out.read().decode(errors="replace")
    return Run(wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024, text)
