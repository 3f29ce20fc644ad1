"""Lint callables for the Dask tests, importable by worker processes: a recording that kills
the process linting it, and one whose lint never returns (both by the recording's name)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.findings import FileReport


def kill_once(path: str, settings: Settings, *, marker: str) -> FileReport:
    """The first process to lint a recording named ``*victim*`` dies (SIGKILL: no clean-up, as
    the OOM killer or a node going away), as if killed from outside mid-run; the next one the
    scheduler gives it to lints it."""
    if "victim" in Path(path).name and not os.path.exists(marker):
        Path(marker).write_text(str(os.getpid()))
        time.sleep(0.2)  # mid-run: the task has started and announced itself
        os.kill(os.getpid(), signal.SIGKILL)
    return lint_file(path, settings)


SLOW_S = 1.2
"""How long a ``*slow*`` recording takes."""


def crash_or_hang(path: str, settings: Settings) -> FileReport:
    """``*crash*``: every process linting it dies; ``*hang*``: its lint never ends; ``*slow*``:
    its lint takes ``SLOW_S`` seconds."""
    name = Path(path).name
    if "slow" in name:
        time.sleep(SLOW_S)
    if "crash" in name:
        time.sleep(0.2)  # a crash mid-lint
        os.kill(os.getpid(), signal.SIGKILL)
    if "hang" in name:
        while True:
            time.sleep(1)
    return lint_file(path, settings)
