"""SARIF 2.1.0 output: validated by Microsoft's SARIF Multitool, and the fields CI services read."""

from __future__ import annotations

import json
import os
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.catalog import PROJECT_URL, load_catalog, render_page
from fuzzoff.config import Settings
from fuzzoff.events import Where
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.profiles import Profile
from fuzzoff.report.junit import render as junit_render
from fuzzoff.report.marks import fingerprint
from fuzzoff.report.sanitize import printable
from fuzzoff.report.sarif import sarif_log
from tests.helpers import ROOT, run_cli
from tests.report_fixtures import gap_recording, hostile_report

MULTITOOL = ROOT / "build" / "node" / "node_modules" / ".bin" / "sarif-multitool"


def multitool() -> Path:
    found = Path(os.environ.get("SARIF_MULTITOOL", MULTITOOL))
    if not found.exists():
        reason = (
            f"SARIF Multitool not found at {found} "
            "(`make test` installs it: npm install @microsoft/sarif-multitool into build/node)"
        )
        if os.environ.get("CI"):
            pytest.fail(reason)
        pytest.skip(reason)
    return found


def validate(tool: Path, logs: list[Path], out: Path) -> list[dict[str, Any]]:
    """Multitool's own findings about ``logs`` (an empty list means valid, no warnings)."""
    proc = subprocess.run(
        [str(tool), "validate", *map(str, logs), "--output", str(out), "--log", "ForceOverwrite"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "DOTNET_SYSTEM_GLOBALIZATION_INVARIANT": "1"},
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    results: list[dict[str, Any]] = json.loads(out.read_text(encoding="utf-8-sig"))["runs"][0][
        "results"
    ]
    return results


def test_multitool_finds_nothing_to_complain_about(tmp_path: Path) -> None:
    tool = multitool()
    hostile = tmp_path / "hostile.sarif"
    hostile.write_text(json.dumps(sarif_log(hostile_report(), Settings())), encoding="utf-8")
    recording = gap_recording(tmp_path / "gap.tlog")
    real = tmp_path / "real.sarif"
    result = run_cli(["lint", str(recording), "--format", "sarif", "--output", str(real)])
    assert result.returncode in (0, 1), result.stderr
    cut = tmp_path / "cut.tlog"
    cut.write_bytes(recording.read_bytes()[:-5])
    incomplete = tmp_path / "incomplete.sarif"
    result = run_cli(["lint", str(cut), "--format", "sarif", "--output", str(incomplete)])
    assert result.returncode == 2, result.stderr
    # A canary with a schema error proves the validator looked (it stays silent on some inputs).
    canary = tmp_path / "canary.sarif"
    log = sarif_log(hostile_report(), Settings())
    # the one result with a byte offset: its region stays valid once startLine is gone
    log["runs"][0]["results"] = [
        r
        for r in log["runs"][0]["results"]
        if "byteOffset" in r["locations"][0]["physicalLocation"]["region"]
    ]
    log["runs"][0]["results"][0]["locations"][0]["physicalLocation"]["region"]["startLine"] = 0
    canary.write_text(json.dumps(log), encoding="utf-8")
    problems = validate(tool, [hostile, real, incomplete, canary], tmp_path / "validation.sarif")
    where = [p["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] for p in problems]
    assert problems and all(uri.endswith("canary.sarif") for uri in where), problems
    assert {p["ruleId"] for p in problems} == {"JSON1008"}


def test_every_rule_is_described_with_its_whole_page() -> None:
    run = sarif_log(Report(), Settings())["runs"][0]
    rules = run["tool"]["driver"]["rules"]
    catalog = load_catalog()
    assert [r["id"] for r in rules] == list(catalog)
    assert run["tool"]["driver"]["informationUri"] == PROJECT_URL
    for descriptor in rules:
        rule = catalog[descriptor["id"]]
        # the page in the repository, derived from the one project address
        assert descriptor["helpUri"] == f"{PROJECT_URL}/blob/main/docs/rules/{rule.code}.md"
        assert (ROOT / rule.page).is_file()
        assert descriptor["help"]["markdown"] == render_page(rule)
        assert descriptor["properties"]["page"] == f"docs/rules/{rule.code}.md"
        assert descriptor["shortDescription"]["text"]
        assert descriptor["fullDescription"]["text"]
        assert "Why is this bad?" in descriptor["help"]["markdown"]
        assert descriptor["defaultConfiguration"]["level"] in ("error", "warning", "note")


def test_a_run_with_unreadable_input_is_not_a_successful_execution(tmp_path: Path) -> None:
    """A truncated tlog: exit status 2, so SARIF says the execution did not succeed, with the
    unreadable part as an error notification, and OFB001's region is the byte its line names."""
    good = gap_recording(tmp_path / "gap.tlog")
    cut = tmp_path / "cut.tlog"
    data = good.read_bytes()
    cut.write_bytes(data[: len(data) - 5])
    result = run_cli(["lint", "gap.tlog", "cut.tlog", "--format", "sarif"], cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    (invocation,) = json.loads(result.stdout)["runs"][0]["invocations"]
    assert invocation["executionSuccessful"] is False
    assert invocation["exitCode"] == 2
    (notice,) = invocation["toolExecutionNotifications"]
    assert notice["level"] == "error" and "cut.tlog" in notice["message"]["text"]
    (unreadable,) = [
        r for r in json.loads(result.stdout)["runs"][0]["results"] if r["ruleId"] == "OFB001"
    ]
    named = int(unreadable["message"]["text"].split(" at byte ")[-1].split()[0])
    assert 0 < named < len(data)
    assert unreadable["locations"][0]["physicalLocation"]["region"]["byteOffset"] == named
    readable = run_cli(["lint", "gap.tlog", "--format", "sarif"], cwd=tmp_path)
    (invocation,) = json.loads(readable.stdout)["runs"][0]["invocations"]
    assert invocation["executionSuccessful"] is True
    assert invocation["exitCode"] == readable.returncode


def test_a_result_without_a_known_byte_has_no_byte_offset() -> None:
    """Byte 0 would name the file's first byte: a finding whose reader gives no offset (a
    whole-file finding, a ULog topic) has line 1 alone."""
    finding = Finding("OFB003", "profile-assumed", Severity.INFO, "assumed")
    report = Report(files=[FileReport("flight.ulg", "ulog", Profile(), findings=[finding])])
    (res,) = sarif_log(report, Settings())["runs"][0]["results"]
    assert res["locations"][0]["physicalLocation"]["region"] == {"startLine": 1}


def test_results_point_at_their_rule_recording_time_and_topic(tmp_path: Path) -> None:
    report = hostile_report()
    run = sarif_log(report, Settings(), root=Path.cwd())["runs"][0]
    rules = run["tool"]["driver"]["rules"]
    results = run["results"]
    assert len(results) == len(report.findings)
    for res, finding in zip(results, report.findings, strict=True):
        assert rules[res["ruleIndex"]]["id"] == res["ruleId"] == finding.code
        level = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "note"}
        assert res["level"] == level[finding.severity]
        # as a terminal shows it: control characters (ANSI escapes) written out as \xNN
        assert printable(finding.message) in res["message"]["text"]
        if finding.time_s is not None:
            assert f"{finding.time_s:.3f} s" in res["message"]["text"]
        if finding.where is not None:
            assert printable(finding.where.topic) in res["message"]["text"]
        location = res["locations"][0]["physicalLocation"]["artifactLocation"]
        # Relative to the working folder, percent-encoded (the hostile path has quotes and <>).
        assert location["uriBaseId"] == "SRCROOT"
        assert not location["uri"].startswith(("/", "file:"))
        assert "<" not in location["uri"] and '"' not in location["uri"]
        assert run["artifacts"][location["index"]]["location"]["uri"] == location["uri"]
    outside = Report(files=[report.files[0]])
    outside.files[0].path = "/elsewhere/flight.tlog"
    artifact = sarif_log(outside, Settings(), root=tmp_path)["runs"][0]["artifacts"][0]
    assert artifact["location"]["uri"] == "file:///elsewhere/flight.tlog"


def test_fingerprints_are_stable_and_tell_findings_apart() -> None:
    first = sarif_log(hostile_report(), Settings())["runs"][0]["results"]
    again = sarif_log(hostile_report(), Settings())["runs"][0]["results"]
    prints = [r["partialFingerprints"]["fuzzoffFinding/v1"] for r in first]
    assert prints == [r["partialFingerprints"]["fuzzoffFinding/v1"] for r in again]
    assert len(set(prints)) == len(prints)
    base = Finding("OFB001", "x", Severity.ERROR, "m", time_s=1.0, where=Where("/a"), vehicle="1")
    variants = [
        Finding("OFB002", "x", Severity.ERROR, "m", time_s=1.0, where=Where("/a"), vehicle="1"),
        Finding("OFB001", "x", Severity.ERROR, "m", time_s=1.0, where=Where("/b"), vehicle="1"),
        Finding("OFB001", "x", Severity.ERROR, "m", time_s=1.0, where=Where("/a"), vehicle="2"),
        Finding("OFB001", "x", Severity.ERROR, "m", time_s=2.0, where=Where("/a"), vehicle="1"),
    ]
    assert all(fingerprint(v) != fingerprint(base) for v in variants)
    # The message wording is not part of the identity: rewording a message keeps the alert.
    reworded = Finding("OFB001", "x", Severity.ERROR, "new", 1.0, Where("/a"), vehicle="1")
    assert fingerprint(reworded) == fingerprint(base)


def test_cli_writes_sarif_with_relative_uri(tmp_path: Path) -> None:
    gap_recording(tmp_path / "gap.tlog")
    result = run_cli(["lint", "gap.tlog", "--format", "sarif"], cwd=tmp_path)
    log = json.loads(result.stdout)
    assert log["version"] == "2.1.0"
    run = log["runs"][0]
    assert run["artifacts"][0]["location"] == {"uri": "gap.tlog", "uriBaseId": "SRCROOT"}
    assert run["originalUriBaseIds"]["SRCROOT"]["uri"] == tmp_path.resolve().as_uri() + "/"
    assert any(r["ruleId"] == "OFB003" for r in run["results"])


@pytest.mark.parametrize("render", ["sarif", "junit"])
def test_a_recordings_text_cannot_forge_lines_in_ci_views(render: str) -> None:
    """A message carrying a line break, a bidi override and 5,000 characters (a hostile topic
    name) stays one line of bounded length, without the override, in SARIF and JUnit alike."""
    forged = "\nFAKE LINE  OFB000 error\u202e" + "B" * 5000
    report = Report(
        files=[
            FileReport(
                path="flight.tlog",
                format="tlog",
                profile=Profile(),
                findings=[Finding("OFB101", "keepalive-below-2hz", Severity.ERROR, forged, 1.0)],
            )
        ]
    )
    if render == "sarif":
        text = sarif_log(report, Settings())["runs"][0]["results"][0]["message"]["text"]
    else:
        failure = ET.fromstring(junit_render(report, Settings())).find(".//failure")
        assert failure is not None and failure.text is not None
        finding_line, rule_line = failure.text.splitlines()  # one line a finding, then the rule
        assert rule_line.startswith("rule OFB101 ")
        text = finding_line
    assert "\n" not in text and "\u202e" not in text and len(text) <= 2000
    assert "\\x0aFAKE LINE" in text
