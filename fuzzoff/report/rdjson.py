"""``--format rdjson``: the Reviewdog Diagnostic Format (one ``DiagnosticResult``), which
``reviewdog -f=rdjson`` turns into review comments, checks or annotations.

Each finding is a diagnostic on its recording with line 1 as its range (a recording is
binary), its rule as ``code`` with the rule's page as ``code.url``, and the tool as
``source``. A recording is rarely a changed line of a pull request's diff, so reviewdog's
default ``-filter-mode=added`` shows nothing: run it with ``-filter-mode=nofilter`` (or
``file``, for the recordings the pull request changed); docs/reports.md has the recipe. The
tests validate every corpus report against reviewdog's own JSON Schema.
"""

from __future__ import annotations

import json
from typing import Any

from fuzzoff.catalog import PROJECT_URL, get_rule
from fuzzoff.config import Settings
from fuzzoff.findings import Report, Severity
from fuzzoff.report.located import Located, located
from fuzzoff.report.marks import message_text
from fuzzoff.report.sanitize import CI_TEXT_LIMIT, escape_bidi, printable

SEVERITY = {Severity.ERROR: "ERROR", Severity.WARNING: "WARNING", Severity.INFO: "INFO"}
SOURCE = {"name": "fuzzoff", "url": PROJECT_URL}


def diagnostic(item: Located) -> dict[str, Any]:
    f = item.finding
    return {
        "message": message_text(f),
        "location": {"path": item.path, "range": {"start": {"line": 1}}},
        "severity": SEVERITY[f.severity],
        "source": SOURCE,
        "code": {"value": f.code, "url": get_rule(f.code).page_url},
        "original_output": printable(f"{f.code} {f.name}: {f.short}", CI_TEXT_LIMIT),
    }


def result_dict(report: Report) -> dict[str, Any]:
    return {"source": SOURCE, "diagnostics": [diagnostic(item) for item in located(report)]}


def render(report: Report, settings: Settings) -> str:
    return escape_bidi(json.dumps(result_dict(report), indent=2, ensure_ascii=False)) + "\n"
