"""The pre-commit hook (``.pre-commit-hooks.yaml``): it picks the recordings out of a commit and
runs its entry on them as pre-commit does (the file names appended), failing the commit on
findings at or above the fail level and passing a clean flight."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

from ruamel.yaml import YAML

from tests.helpers import CORPORA, ROOT

(HOOK,) = YAML(typ="safe").load((ROOT / ".pre-commit-hooks.yaml").read_text(encoding="utf-8"))


def run_hook(*files: Path) -> subprocess.CompletedProcess[str]:
    """The entry with the staged file names, as pre-commit runs a ``language: python`` hook:
    the command from the environment fuzzoff is installed in, in the repository's root."""
    argv = shlex.split(HOOK["entry"])
    command = [str(Path(sys.executable).parent / argv[0]), *argv[1:]]
    return subprocess.run(
        [*command, *(str(f.relative_to(ROOT)) for f in files)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "NO_COLOR": "1"},
    )


def test_the_hook_takes_recordings_of_every_format_and_nothing_else() -> None:
    assert HOOK["id"] == "fuzzoff" and HOOK["language"] == "python"
    files = re.compile(HOOK["files"])
    for name in ("flight.tlog", "LOG001.ULG", "run.mcap", "mavros.bag", "bag_0.db3"):
        assert files.search(f"logs/{name}"), name
    for name in ("README.md", "flight.tlog.expected.json", "metadata.yaml", "notes.txt"):
        assert not files.search(f"logs/{name}"), name
    taken = [p for p in CORPORA.rglob("*") if p.is_file() and files.search(p.as_posix())]
    assert {p.suffix for p in taken} >= {".tlog", ".ulg", ".mcap", ".bag", ".db3"}


def test_the_hook_fails_a_commit_with_a_lost_stream_and_passes_a_clean_flight() -> None:
    bad = run_hook(CORPORA / "tlog" / "stream_lost_in_offboard.tlog")
    assert bad.returncode == 1, bad.stderr
    assert "OFB101 error" in bad.stdout and "OFB103 error" in bad.stdout
    good = run_hook(CORPORA / "tlog" / "good_offboard.tlog", CORPORA / "ulog" / "good_offboard.ulg")
    assert good.returncode == 0, good.stdout + good.stderr
    assert "result: passed" in good.stdout


def test_the_hook_reports_a_damaged_recording_in_one_line_and_fails() -> None:
    result = run_hook(CORPORA / "tlog" / "truncated.tlog")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "truncated.tlog" in result.stderr
    assert "Traceback" not in result.stderr
