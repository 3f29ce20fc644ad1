"""Issue 17's acceptance on recordings real programs wrote: real PX4 SITL (its ULog and the
offboard link's tlog) flown by pymavlink scenario programs and by real MAVSDK 3 and 4.

- every *clean* recording lints with exit 0 at the default fail level;
- every *hazard* recording gives one of its error codes;
- every real PX4 tlog reads with exit 0 or 1 (never "unreadable").

What each recording is, and which program on which PX4 wrote it, is in its
``corpora/sitl/NAME.expected.json`` (``kind``, ``hazard``, ``program``, ``px4_release``) and in
``corpora/sitl/README.md``. Where today's rules still fail a case, it is a strict xfail whose
reason names the issue and the rule (from the expected file's ``known_false``), so it flips
when the fix lands.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import CORPORA, run_cli

SITL = CORPORA / "sitl"
SPECS = sorted(SITL.glob("*.expected.json"))

HAZARD_MISSED = {
    "OFB107": "issue 17: OFB107 is a warning for a velocity frozen at 2 m/s for 20 s (an error"
    " by the new severity principle)",
    "OFB404": "issue 17: OFB404 is a warning for a climb written in ENU from the ground, and"
    " misses ENU z when the vehicle is airborne",
}


def _spec(path: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(path.read_text())
    return data


def _name(path: Path) -> str:
    return path.name.removesuffix(".expected.json")


def _short(spec: dict[str, Any], path: Path) -> str:
    """'issue 17: OFB107 warning, ...' from the expected file's known_false (which says why)."""
    by_issue: dict[str, list[str]] = {}
    for entry in spec.get("known_false", []):
        finding, _, why = entry.partition(": ")
        issue = why.split(":")[0] if why.startswith("issue") else "to review"
        by_issue.setdefault(issue, []).append(finding)
    parts = [f"{issue}: {', '.join(found)}" for issue, found in sorted(by_issue.items())]
    return "; ".join(parts) + f" (why: known_false in {path.name})"


def _clean_cases() -> list[Any]:
    cases = []
    for path in SPECS:
        spec = _spec(path)
        if spec["kind"] != "clean":
            continue
        marks = []
        if spec["exit_status"] != 0:
            marks.append(pytest.mark.xfail(strict=True, reason=_short(spec, path)))
        cases.append(pytest.param(path, marks=marks, id=_name(path)))
    return cases


def _hazard_cases() -> list[Any]:
    cases = []
    for path in SPECS:
        spec = _spec(path)
        if spec["kind"] != "hazard":
            continue
        errors = {f["code"] for f in spec["findings"] if f["severity"] == "error"}
        marks = []
        if not errors & set(spec["hazard"]):
            reasons = [HAZARD_MISSED.get(c, f"{c} not given") for c in spec["hazard"]]
            marks.append(pytest.mark.xfail(strict=True, reason="; ".join(reasons)))
        cases.append(pytest.param(path, marks=marks, id=_name(path)))
    return cases


def _tlog_cases() -> list[Any]:
    cases = []
    for path in SPECS:
        spec = _spec(path)
        if not spec["recording"].endswith(".tlog"):
            continue
        marks = []
        if spec["exit_status"] == 2:
            marks.append(
                pytest.mark.xfail(
                    strict=True,
                    reason="issue 17: PX4's MAVLink 'development' ids (8, 380, 410, 411, 436) are"
                    " read as OFB001 with the 'common' dialect",
                )
            )
        cases.append(pytest.param(path, marks=marks, id=_name(path)))
    return cases


@functools.cache
def _lint(spec_path: Path) -> tuple[int, list[dict[str, Any]]]:
    recording = spec_path.parent / _spec(spec_path)["recording"]
    out = run_cli(["lint", str(recording), "--format", "json"])
    (report,) = json.loads(out.stdout)["files"]
    return out.returncode, report["findings"]


def test_the_corpus_holds_clean_and_hazard_recordings_of_real_px4_and_real_mavsdk() -> None:
    specs = [_spec(p) for p in SPECS]
    kinds = {s["kind"] for s in specs}
    assert {"clean", "hazard"} <= kinds <= {"clean", "hazard", "context"}
    assert all(s.get("context") for s in specs if s["kind"] == "context")
    assert any(s["program"].startswith("MAVSDK 3") for s in specs)
    assert any(s["program"].startswith("MAVSDK 4") for s in specs)
    releases = {s["px4_release"] for s in specs}
    assert len(releases) >= 3, releases


@pytest.mark.parametrize("spec_path", _clean_cases())
def test_a_clean_recording_lints_with_exit_0(spec_path: Path) -> None:
    status, findings = _lint(spec_path)
    loud = [f"{f['code']} {f['severity']}" for f in findings if f["severity"] != "info"]
    assert status == 0, loud


@pytest.mark.parametrize("spec_path", _hazard_cases())
def test_a_hazard_recording_gives_its_error(spec_path: Path) -> None:
    _, findings = _lint(spec_path)
    codes = set(_spec(spec_path)["hazard"])
    assert any(f["code"] in codes and f["severity"] == "error" for f in findings), codes


@pytest.mark.parametrize("spec_path", _tlog_cases())
def test_a_real_px4_tlog_reads_with_exit_0_or_1(spec_path: Path) -> None:
    status, findings = _lint(spec_path)
    assert status in (0, 1), [f["code"] for f in findings if f["code"] == "OFB001"]
