"""``--format sarif``: SARIF 2.1.0 for code-scanning services (GitHub, Azure DevOps, ...).

Every catalog rule is in ``tool.driver.rules`` with its whole page as help text (plain and
Markdown), which GitHub code scanning shows beside each result, and its page in the project's
repository as ``helpUri``; the tool's ``informationUri`` is the repository itself. Both come
from ``catalog.PROJECT_URL``. A recording is binary, so a result points at the file with a
region of line 1 and, where the reader knows it, the byte offset (for OFB001 and OFB004 the
byte their line names); the time, vehicle and topic go into the message and the result's
properties, and ``partialFingerprints`` is computed here from rule, vehicle, topic and time
window (GitHub cannot fingerprint a binary file itself). Paths under the working folder are
written relative to the ``SRCROOT`` base, which is what code scanning matches against the
repository. A run with input that could not be read completely (exit status 2) is not a
successful execution: ``executionSuccessful`` is false and each unreadable part is an error
notification.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any
from urllib.parse import quote

from fuzzoff import __version__
from fuzzoff.catalog import PROJECT_URL, Rule, load_catalog, render_page
from fuzzoff.config import Settings
from fuzzoff.findings import Finding, Report, Severity
from fuzzoff.report import CampaignReport
from fuzzoff.report.marks import marks, message_text
from fuzzoff.report.sanitize import CI_TEXT_LIMIT, escape_bidi, printable

SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
INFORMATION_URI = PROJECT_URL
"""Where the tool is described: its repository (the README)."""
FINGERPRINT_KEY = "fuzzoffFinding/v1"
LEVEL = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "note"}
BASE_ID = "SRCROOT"


def _first_sentence(text: str) -> str:
    flat = " ".join(text.split())
    head, dot, _ = flat.partition(". ")
    return head + "." if dot else flat


def rule_descriptor(rule: Rule) -> dict[str, Any]:
    page = render_page(rule)
    return {
        "id": rule.code,
        "name": "".join(part.capitalize() for part in rule.name.split("-")),
        "shortDescription": {"text": _first_sentence(rule.summary)},
        "fullDescription": {"text": " ".join(rule.summary.split())},
        "help": {"text": page, "markdown": page},
        "helpUri": rule.page_url,
        "defaultConfiguration": {"level": LEVEL[rule.severity]},
        "properties": {
            "tags": ["px4", "offboard", *(["heuristic"] if rule.heuristic else [])],
            "precision": "medium" if rule.heuristic else "high",
            "profiles": rule.profiles_text(),
            "page": rule.page,
        },
    }


def artifact_uri(path: str, root: Path) -> tuple[str, str | None]:
    """A relative URI under ``root`` (with its base id) where possible, else an absolute one."""
    resolved = Path(path).resolve()
    try:
        relative = resolved.relative_to(root)
    except ValueError:
        return resolved.as_uri(), None
    return quote(relative.as_posix()), BASE_ID


def region(finding: Finding) -> dict[str, int]:
    """``startLine`` 1, and the byte offset where the reader knows it (none where it does not:
    byte 0 would name the file's first byte).

    GitHub code scanning places results by line and does not read ``byteOffset``, so a binary
    recording gets line 1 beside the SARIF binary form.
    """
    offset = finding.where.offset if finding.where is not None else None
    return {"startLine": 1} if offset is None else {"startLine": 1, "byteOffset": offset}


def result(
    finding: Finding, rule_index: int, artifact: dict[str, Any], mark: str
) -> dict[str, Any]:
    props: dict[str, Any] = {"vehicle": finding.vehicle}
    if finding.time_s is not None:
        props["time_s"] = round(finding.time_s, 6)
    if finding.end_s is not None:
        props["end_s"] = round(finding.end_s, 6)
    if finding.where is not None and finding.where.topic:
        props["topic"] = finding.where.topic
        if finding.where.index is not None:
            props["index"] = finding.where.index
        if finding.where.offset is not None:
            props["byte_offset"] = finding.where.offset
    return {
        "ruleId": finding.code,
        "ruleIndex": rule_index,
        "level": LEVEL[finding.severity],
        "message": {"text": message_text(finding)},
        "locations": [
            {"physicalLocation": {"artifactLocation": artifact, "region": region(finding)}}
        ],
        "partialFingerprints": {FINGERPRINT_KEY: mark},
        "properties": props,
    }


def sarif_log(report: Report, settings: Settings, root: Path | None = None) -> dict[str, Any]:
    root = (root or Path.cwd()).resolve()
    catalog = load_catalog()
    index = {code: i for i, code in enumerate(catalog)}
    artifacts: list[dict[str, Any]] = []
    results: list[dict[str, Any]] = []
    notifications: list[dict[str, Any]] = []
    for file in report.files:
        uri, base = artifact_uri(file.path, root)
        location: dict[str, Any] = {"uri": uri, **({"uriBaseId": base} if base else {})}
        artifacts.append({"location": location, "properties": {"format": file.format}})
        ref = {**location, "index": len(artifacts) - 1}
        for finding, mark in zip(file.findings, marks(file.findings), strict=True):
            results.append(result(finding, index[finding.code], ref, mark))
        # a suppressed finding (configuration or baseline) stays a result, marked suppressed:
        # code scanning then shows it as such instead of taking it for fixed
        held = [finding for finding, _ in file.suppressed]
        for (finding, why), mark in zip(file.suppressed, marks(held), strict=True):
            item = result(finding, index[finding.code], ref, mark)
            justification = printable(f"{why.kind}: {why.reason}", CI_TEXT_LIMIT)
            item["suppressions"] = [{"kind": "external", "justification": justification}]
            results.append(item)
        notifications.extend(
            {
                "level": "error",
                "message": {"text": printable(line, CI_TEXT_LIMIT)},
                "locations": [{"physicalLocation": {"artifactLocation": ref}}],
            }
            for line in file.problems
        )
    run: dict[str, Any] = {
        "tool": {
            "driver": {
                "name": "fuzzoff",
                "version": __version__,
                "semanticVersion": __version__,
                "informationUri": INFORMATION_URI,
                "rules": [rule_descriptor(rule) for rule in catalog.values()],
            }
        },
        "invocations": [
            {
                # input that could not be read completely: the analysis did not complete
                "executionSuccessful": report.complete,
                "exitCode": settings.exit_status(report),
                "toolExecutionNotifications": notifications,
                "properties": {"fail_on": settings.fail_on.label, "complete": report.complete},
            }
        ],
        "originalUriBaseIds": {BASE_ID: {"uri": root.as_uri() + "/"}},
        "artifacts": artifacts,
        "results": results,
    }
    return {"$schema": SCHEMA, "version": "2.1.0", "runs": [run]}


def render(report: Report, settings: Settings) -> str:
    return escape_bidi(json.dumps(sarif_log(report, settings), indent=2, ensure_ascii=False)) + "\n"


def render_campaign(campaign: CampaignReport) -> str:
    """``fuzzoff fuzz --format sarif``: one rule per property (``fuzz/<name>``), one result per
    counterexample, located at the saved reproducer (an artifact, so code scanning shows it
    where it was committed)."""
    result, saved = campaign.result, campaign.saved
    root = Path.cwd().resolve()
    rules = [
        {
            "id": f"fuzz/{r.name}",
            "name": "".join(p.capitalize() for p in r.name.split("-")),
            "shortDescription": {"text": r.claim},
            "defaultConfiguration": {"level": "error"},
        }
        for r in result.results
    ]
    results = []
    for r in result.results:
        if not r.failed:
            continue
        item: dict[str, Any] = {
            "ruleId": f"fuzz/{r.name}",
            "level": "error",
            "message": {"text": "; ".join(r.problems)[:2000]},
            "properties": {
                "counterexample": None if r.counterexample is None else r.counterexample.describe(),
                "seed": result.config.seed,
            },
        }
        if r.name in saved:
            # As lint writes it: relative to the working folder (SRCROOT), percent-encoded.
            uri, base = artifact_uri(str(saved[r.name]), root)
            location = {"uri": uri, **({"uriBaseId": base} if base else {})}
            item["locations"] = [{"physicalLocation": {"artifactLocation": location}}]
        results.append(item)
    doc = {
        "$schema": SCHEMA,
        "version": "2.1.0",
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "fuzzoff",
                        "version": __version__,
                        "informationUri": INFORMATION_URI,
                        "rules": rules,
                    }
                },
                "originalUriBaseIds": {BASE_ID: {"uri": root.as_uri() + "/"}},
                "results": results,
            }
        ],
    }
    return json.dumps(doc, indent=2) + "\n"
