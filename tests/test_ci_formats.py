"""The CI formats (``github``, ``rdjson``, ``gitlab``, ``json-lines``) and the JSON report's
schema: ``check_ci_reports`` checks each report against its consumer's schema or rules (every
corpus folder's, in ``tests/test_outputs_same_story.py``, which lints each folder once for all
formats), and the escaping that keeps a recording's text inside its own annotation."""

from __future__ import annotations

import json
import re
from functools import cache
from pathlib import Path
from typing import Any

import jsonschema

from fuzzoff.config import Settings
from fuzzoff.events import Where
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.profiles import Profile
from fuzzoff.report import FORMATS, renderer
from fuzzoff.report.json_report import SCHEMA_FILE
from tests.helpers import ROOT, run_cli
from tests.report_fixtures import gap_recording, hostile_report

SCHEMAS = Path(__file__).parent / "schemas"
CI_FORMATS = ("json", "rdjson", "gitlab", "github", "json-lines")
GITLAB_SEVERITIES = {"info", "minor", "major", "critical", "blocker"}


@cache
def lint_report_validator() -> jsonschema.protocols.Validator:
    schema = json.loads(SCHEMA_FILE.read_text(encoding="utf-8"))
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


@cache
def rdjson_validator() -> jsonschema.protocols.Validator:
    schema = json.loads((SCHEMAS / "reviewdog-DiagnosticResult.json").read_text(encoding="utf-8"))
    return jsonschema.Draft4Validator(schema)


def errors(validator: jsonschema.protocols.Validator, doc: Any) -> list[str]:
    return [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(doc)][:5]


_COMMAND = re.compile(r"^::(error|warning|notice) ([^:]*)::(.*)$")


def unescape(text: str) -> str:
    """What the Actions runner makes of an escaped value (``%25`` last, as it decodes)."""
    for escaped, plain in (("%0D", "\r"), ("%0A", "\n"), ("%3A", ":"), ("%2C", ","), ("%25", "%")):
        text = text.replace(escaped, plain)
    return text


def parse_github(text: str) -> list[tuple[str, dict[str, str], str]]:
    """Workflow commands as the runner reads them: the command, its properties (split at each
    ``,``, then at the first ``=``), its message. Any other line is a test failure."""
    out = []
    for line in text.splitlines():
        match = _COMMAND.match(line)
        assert match, f"not a workflow command: {line!r}"
        props = dict(p.split("=", 1) for p in match.group(2).split(","))
        out.append((match.group(1), {k: unescape(v) for k, v in props.items()}, match.group(3)))
    return out


def check_ci_reports(outputs: dict[str, str]) -> None:
    """Each report valid for its consumer, and all of them about the same findings."""
    report = json.loads(outputs["json"])
    assert not errors(lint_report_validator(), report)
    findings = [(f["path"], x) for f in report["files"] for x in f["findings"]]

    rdjson = json.loads(outputs["rdjson"])
    assert not errors(rdjson_validator(), rdjson)
    diagnostics = rdjson["diagnostics"]
    assert [d["code"]["value"] for d in diagnostics] == [x["code"] for _, x in findings]
    for d in diagnostics:  # what the schema leaves optional and reviewdog needs
        assert d["location"]["path"] and d["location"]["range"]["start"]["line"] == 1
        assert d["severity"] in {"ERROR", "WARNING", "INFO"}

    issues = json.loads(outputs["gitlab"])
    assert isinstance(issues, list) and len(issues) == len(findings)
    for issue in issues:
        assert isinstance(issue["description"], str) and issue["description"]
        assert re.fullmatch(r"OFB\d{3}", issue["check_name"])
        assert issue["severity"] in GITLAB_SEVERITIES
        assert isinstance(issue["location"]["path"], str) and issue["location"]["path"]
        assert isinstance(issue["location"]["lines"]["begin"], int)
    fingerprints = [i["fingerprint"] for i in issues]
    assert len(set(fingerprints)) == len(fingerprints), "GitLab needs one fingerprint an issue"

    commands = parse_github(outputs["github"])
    level = {"error": "error", "warning": "warning", "info": "notice"}
    assert [c for c, _, _ in commands] == [level[x["severity"]] for _, x in findings]
    assert all(p["line"] == "1" and p["file"] for _, p, _ in commands)

    lines = [json.loads(line) for line in outputs["json-lines"].splitlines()]
    assert [(x["path"], x["code"], x["fingerprint"]) for x in lines] == [
        (path, x["code"], x["fingerprint"]) for path, x in findings
    ]


def test_hostile_text_stays_inside_its_report() -> None:
    outputs = {fmt: renderer(fmt)(hostile_report(), Settings()) for fmt in CI_FORMATS}
    check_ci_reports(outputs)
    for _, _, message in parse_github(outputs["github"]):
        assert "\x1b" not in message and "\n" not in unescape(message)


def test_github_escapes_as_the_runner_reads() -> None:
    finding = Finding(
        "OFB101",
        "keepalive-below-2hz",
        Severity.ERROR,
        "100% gone\r\nin: a, b",
        time_s=2.0,
        where=Where("SET_POSITION_TARGET_LOCAL_NED", index=3),
    )
    path = "flights/a:b,c%d.tlog"
    report = Report([FileReport(path, "tlog", Profile("1.15", "mc"), findings=[finding])])
    (line,) = renderer("github")(report, Settings()).splitlines()
    assert line.startswith("::error file=flights/a%3Ab%2Cc%25d.tlog,line=1,title=")
    ((_, props, message),) = parse_github(line)
    assert props["file"] == path
    assert props["title"] == "fuzzoff OFB101 (keepalive-below-2hz)"
    assert "100%25 gone" in message and "%3A" not in message  # data keeps : and ,
    assert unescape(message).startswith(f"{path}: 2.000s OFB101 100% gone")


def test_severities_map_to_each_consumer() -> None:
    findings = [
        Finding("OFB101", "keepalive-below-2hz", sev, "m", time_s=float(i))
        for i, sev in enumerate(Severity)
    ]
    report = Report([FileReport("a.tlog", "tlog", Profile(), findings=findings)])
    gh = [c for c, _, _ in parse_github(renderer("github")(report, Settings()))]
    assert gh == ["notice", "warning", "error"]
    rd = json.loads(renderer("rdjson")(report, Settings()))["diagnostics"]
    assert [d["severity"] for d in rd] == ["INFO", "WARNING", "ERROR"]
    gl = json.loads(renderer("gitlab")(report, Settings()))
    assert [i["severity"] for i in gl] == ["info", "major", "critical"]


def test_fingerprints_stay_from_one_lint_to_the_next(tmp_path: Path) -> None:
    recording = gap_recording(tmp_path / "gap.tlog")
    first = run_cli(["lint", "gap.tlog", "--format", "gitlab"], cwd=tmp_path)
    second = run_cli(["lint", str(recording), "--format", "gitlab"], cwd=tmp_path)
    assert first.returncode == second.returncode == 1
    assert first.stdout == second.stdout  # the same path, the same issues, the same prints
    issues = json.loads(first.stdout)
    assert issues and all(i["location"]["path"] == "gap.tlog" for i in issues)


def test_the_formats_are_offered_and_the_exit_status_is_the_same(tmp_path: Path) -> None:
    assert set(CI_FORMATS) <= set(FORMATS)
    gap_recording(tmp_path / "gap.tlog")
    for fmt in CI_FORMATS:
        assert run_cli(["lint", "gap.tlog", "--format", fmt], cwd=tmp_path).returncode == 1


def test_the_schema_ships_in_the_package_and_reports_name_it() -> None:
    assert SCHEMA_FILE.is_file() and SCHEMA_FILE.is_relative_to(ROOT / "fuzzoff")
    docs = (ROOT / "docs" / "reports.md").read_text(encoding="utf-8")
    assert "fuzzoff/report/schemas/lint-report.schema.json" in docs
