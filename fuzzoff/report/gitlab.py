"""``--format gitlab``: a GitLab Code Quality report (the Code Climate issue list GitLab
reads from ``artifacts:reports:codequality``), shown in the merge request's widget and diff.

One issue per finding: ``description`` (the message, with time, vehicle and topic),
``check_name`` (the rule code), ``fingerprint`` (``Located.fingerprint``: the SARIF fingerprint
with the path, so the same finding in the next pipeline is the same issue and a fixed one shows
as resolved), ``severity`` (error ``critical``, warning ``major``, info ``info``: an error is a
flight that PX4 would take out of offboard control) and ``location.path`` with
``location.lines.begin`` 1 (a recording is binary).
"""

from __future__ import annotations

import json
from typing import Any

from fuzzoff.config import Settings
from fuzzoff.findings import Report, Severity
from fuzzoff.report.located import Located, located
from fuzzoff.report.marks import message_text
from fuzzoff.report.sanitize import escape_bidi

SEVERITY = {Severity.ERROR: "critical", Severity.WARNING: "major", Severity.INFO: "info"}


def issue(item: Located) -> dict[str, Any]:
    f = item.finding
    return {
        "type": "issue",
        "description": f"{f.code} {message_text(f)}",
        "check_name": f.code,
        "categories": ["Bug Risk"],
        "fingerprint": item.fingerprint,
        "severity": SEVERITY[f.severity],
        "location": {"path": item.path, "lines": {"begin": 1}},
    }


def issues(report: Report) -> list[dict[str, Any]]:
    return [issue(item) for item in located(report)]


def render(report: Report, settings: Settings) -> str:
    return escape_bidi(json.dumps(issues(report), indent=2, ensure_ascii=False)) + "\n"
