"""Replay every recording in corpora/ through the CLI and compare with its expected findings.

Each ``corpora/**/NAME.expected.json`` names its ``recording`` (relative to the JSON file), the
extra command-line ``args``, the ``exit_status``, whether the file is ``complete``, and the exact
list of ``findings`` (``code``, ``severity``, ``time_s`` or null, optional ``vehicle``). Times
match within ``TIME_TOLERANCE_S``; every finding must be listed (no extras, none missing).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import run_cli

CORPORA = Path(__file__).resolve().parent.parent / "corpora"
TIME_TOLERANCE_S = 0.05

EXPECTED = sorted(CORPORA.rglob("*.expected.json"))


def _key(finding: dict[str, Any]) -> tuple[str, str, str]:
    return (finding["code"], finding["severity"], finding.get("vehicle", ""))


def _match(expected: list[dict[str, Any]], actual: list[dict[str, Any]]) -> list[str]:
    """Pair expected with actual findings; return what is missing or extra."""
    remaining = list(actual)
    problems = []
    for want in expected:
        hit = None
        for got in remaining:
            if _key(got) != _key({**want, "vehicle": want.get("vehicle", got.get("vehicle", ""))}):
                continue
            if want.get("time_s") is None or got["time_s"] is None:
                if want.get("time_s") is None and got["time_s"] is None:
                    hit = got
                    break
                continue
            if abs(want["time_s"] - got["time_s"]) <= TIME_TOLERANCE_S:
                hit = got
                break
        if hit is None:
            problems.append(f"missing {want}")
        else:
            remaining.remove(hit)
    problems += [
        f"unexpected {f['code']} {f['severity']} t={f['time_s']}: {f['message']}" for f in remaining
    ]
    return problems


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
    problems = _match(spec["findings"], file_report["findings"])
    assert not problems, "\n".join(problems)
    if "profile" in spec:
        for key, value in spec["profile"].items():
            assert file_report["profile"][key] == value, key


def test_corpus_recordings_stay_small() -> None:
    for path in CORPORA.rglob("*"):
        if path.is_file():
            assert path.stat().st_size < 1_000_000, f"{path} is over 1 MB"
