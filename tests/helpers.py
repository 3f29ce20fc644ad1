"""Shared test helpers: run the real CLI in-process (fast) or as a subprocess (end to end)."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from fuzzoff.cli import main

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
