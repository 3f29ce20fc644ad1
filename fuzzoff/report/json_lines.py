"""``--format json-lines``: one finding per line, each a JSON object with the recording's
``path``, ``format`` and profile beside the finding's fields of the JSON report (its
``fingerprint`` the SARIF one, as there), for ``jq``, ``grep`` and a fleet's log store. A
recording without findings writes no line; nothing else is written."""

from __future__ import annotations

import json
from typing import Any

from fuzzoff.config import Settings
from fuzzoff.findings import Report
from fuzzoff.report.json_report import clean
from fuzzoff.report.located import Located, located
from fuzzoff.report.sanitize import escape_bidi


def line(item: Located) -> dict[str, Any]:
    profile = item.file.profile
    return {
        "path": item.file.path,
        "format": item.file.format,
        "px4": profile.px4,
        "vehicle_type": profile.vehicle,
        **clean(item.finding.to_json()),
        "fingerprint": item.mark,
    }


def render(report: Report, settings: Settings) -> str:
    return "".join(
        escape_bidi(json.dumps(line(item), ensure_ascii=False)) + "\n" for item in located(report)
    )
