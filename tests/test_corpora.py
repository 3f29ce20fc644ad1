"""Replay every recording in corpora/ through the CLI and compare with its expected findings.

Each ``corpora/**/NAME.expected.json`` names its ``recording`` (relative to the JSON file), the
extra command-line ``args``, the ``exit_status``, whether the file is ``complete``, and the exact
list of ``findings`` (``code``, ``severity``, ``time_s`` or null, optional ``vehicle``), paired
as ``fuzzoff replay`` pairs them (``compare``: times within ``TIME_TOLERANCE_S``); every finding
must be listed (no extras, none missing). An optional ``stderr`` lists what the lines about the
file's damage must say.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fuzzoff.commands.replay import compare
from tests.helpers import run_cli

CORPORA = Path(__file__).resolve().parent.parent / "corpora"

EXPECTED = sorted(CORPORA.rglob("*.expected.json"))


@pytest.mark.parametrize(
    "expected_file", EXPECTED, ids=[str(p.relative_to(CORPORA)) for p in EXPECTED]
)
def test_corpus_recording_gives_expected_findings(expected_file: Path) -> None:
    spec = json.loads(expected_file.read_text())
    recording = expected_file.parent / spec["recording"]
    assert recording.exists(), f"{recording} is missing"
    result = run_cli(["lint", str(recording), "--format", "json", *spec.get("args", [])])
    assert result.returncode == spec["exit_status"], result.stderr
    data = json.loads(result.stdout)
    (file_report,) = data["files"]
    assert file_report["complete"] is spec.get("complete", True)
    problems = compare(spec["findings"], file_report["findings"])
    assert not problems, "\n".join(problems)
    if "profile" in spec:
        for key, value in spec["profile"].items():
            assert file_report["profile"][key] == value, key
    for says in spec.get("stderr", []):
        assert says in result.stderr, result.stderr


def test_corpus_recordings_stay_small() -> None:
    for path in CORPORA.rglob("*"):
        if path.is_file():
            assert path.stat().st_size < 1_000_000, f"{path} is over 1 MB"
