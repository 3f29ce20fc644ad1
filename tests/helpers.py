"""Shared test helpers: run the real CLI in-process (fast) or as a subprocess (end to end); build
floats as readers do and order findings as lint does (the runs-vs-single-message tests)."""

from __future__ import annotations

import contextlib
import io
import math
import os
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fuzzoff.cli import main
from fuzzoff.findings import Finding

ROOT = Path(__file__).resolve().parent.parent
CORPORA = ROOT / "corpora"


@dataclass
class CliResult:
    returncode: int
    stdout: str
    stderr: str


def run_cli(args: Sequence[str], cwd: Path | None = None) -> CliResult:
    """``fuzzoff ARGS`` in this process, with stdout and stderr captured."""
    out, err = io.StringIO(), io.StringIO()
    old = Path.cwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(list(args))
    finally:
        os.chdir(old)
    return CliResult(code, out.getvalue(), err.getvalue())


def run_cli_process(
    args: Sequence[str], cwd: Path | None = None, timeout: float = 300
) -> CliResult:
    """``fuzzoff ARGS`` as a real process, as a user or CI would run it."""
    proc = subprocess.run(
        [sys.executable, "-m", "fuzzoff.cli", *args],
        cwd=cwd or ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "NO_COLOR": "1"},
    )
    return CliResult(proc.returncode, proc.stdout, proc.stderr)


def fresh(value: Any, new: bool = True) -> Any:
    """A new float object with the same bits (NaN included), as a reader builds one; or the
    same object (``new`` false), as the events' defaults share one NaN."""
    return value * 1.0 if new and isinstance(value, float) else value


def in_lint_order(findings: list[Finding]) -> list[Finding]:
    """One vehicle's findings sorted as lint sorts them (a run reports when it is handed over,
    after checks that took the messages one at a time)."""
    return sorted(findings, key=lambda f: (-math.inf if f.time_s is None else f.time_s, f.code))
