"""JUnit XML as CI systems read it (parsed back with junitparser)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

from junitparser import Failure, JUnitXml, Skipped, TestCase, TestSuite

from fuzzoff.catalog import get_rule, load_catalog
from fuzzoff.config import Settings
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.profiles import Profile
from fuzzoff.report.junit import render
from tests.helpers import run_cli
from tests.report_fixtures import gap_recording, hostile_report


def parse(text: str, tmp_path: Path) -> list[TestSuite]:
    path = tmp_path / "junit.xml"
    path.write_text(text, encoding="utf-8")
    return list(JUnitXml.fromfile(str(path)))


def cases(suite: TestSuite) -> dict[str, TestCase]:
    return {case.name.split()[0]: case for case in suite}


def outcome(case: TestCase) -> str:
    kinds = {type(r) for r in case.result}
    if Failure in kinds:
        return "failed"
    if Skipped in kinds:
        return "skipped"
    return "passed"


def one_file(findings: list[Finding], profile: Profile | None = None) -> Report:
    file = FileReport("flight.tlog", "tlog", profile or Profile("1.15", "mc", True, True))
    file.findings = findings
    file.stats = {"events": 10}
    return Report(files=[file])


def test_one_suite_per_recording_one_case_per_rule(tmp_path: Path) -> None:
    report = hostile_report()
    suites = parse(render(report, Settings()), tmp_path)
    assert [s.name for s in suites] == [f.path for f in report.files]
    for suite in suites:
        assert list(cases(suite)) == list(load_catalog())
    hostile, unreadable = suites
    failed = cases(hostile)["OFB001"]
    assert outcome(failed) == "failed"
    text = failed.result[0].text
    assert "9.000 s" in text and "\\x1b[2J" in text and "\x1b" not in text
    assert f"fuzzoff rule OFB001, or {get_rule('OFB001').page}" in text
    # The unreadable recording fails OFB001 and skips what it could not show.
    assert outcome(cases(unreadable)["OFB001"]) == "failed"
    assert outcome(cases(unreadable)["OFB101"]) == "skipped"


def test_fail_level_decides_failed_or_passed(tmp_path: Path) -> None:
    code = next(r.code for r in load_catalog().values() if r.severity == Severity.WARNING)
    warning = Finding(code, get_rule(code).name, Severity.WARNING, "a gap", time_s=2.0)
    report = one_file([warning])
    strict = cases(parse(render(report, Settings()), tmp_path)[0])[code]
    assert outcome(strict) == "failed"
    lenient_settings = replace(Settings(), fail_on=Severity.ERROR)
    lenient = cases(parse(render(report, lenient_settings), tmp_path)[0])[code]
    assert outcome(lenient) == "passed"
    assert "a gap" in (lenient.system_out or "")


def test_skipped_when_not_checkable_or_not_for_this_profile(tmp_path: Path) -> None:
    mc_rule = next(
        r for r in load_catalog().values() if r.applies_to("1.15", "mc") and r.code != "OFB002"
    )
    other = next(r for r in load_catalog().values() if not r.applies_to("1.15", "mc"))
    note = Finding(
        "OFB002",
        "rule-not-checkable",
        Severity.INFO,
        f"1 rule cannot be checked on this recording: {mc_rule.code} ({mc_rule.name}) "
        "needs vehicle_status",
    )
    by_code = cases(parse(render(one_file([note]), Settings()), tmp_path)[0])
    assert outcome(by_code[mc_rule.code]) == "skipped"
    assert "needs vehicle_status" in by_code[mc_rule.code].result[0].message
    assert outcome(by_code[other.code]) == "skipped"
    assert "does not apply" in by_code[other.code].result[0].message
    passed = [c for c, case in by_code.items() if outcome(case) == "passed"]
    assert mc_rule.code not in passed and passed


def test_selected_rules_only(tmp_path: Path) -> None:
    settings = replace(Settings(), select=frozenset({"OFB001", "OFB003"}))
    suite = parse(render(one_file([]), settings), tmp_path)[0]
    assert list(cases(suite)) == ["OFB001", "OFB003"]


def test_cli_junit_matches_json_findings(tmp_path: Path) -> None:
    recording = gap_recording(tmp_path / "gap.tlog")
    out = tmp_path / "report.xml"
    result = run_cli(["lint", str(recording), "--format", "junit", "--output", str(out)])
    as_json = json.loads(run_cli(["lint", str(recording), "--format", "json"]).stdout)
    suite = next(iter(JUnitXml.fromfile(str(out))))
    failing = {f["code"] for f in as_json["files"][0]["findings"] if f["severity"] != "info"}
    assert failing, "the gap recording should break at least one warning/error rule"
    assert {c for c, case in cases(suite).items() if outcome(case) == "failed"} == failing
    assert result.returncode == (1 if failing else 0)
