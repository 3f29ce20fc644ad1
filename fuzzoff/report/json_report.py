"""``--format json``: the stable machine-readable shape of spec/interface.md."""

from __future__ import annotations

import json
import math
from typing import Any

from fuzzoff import __version__
from fuzzoff.config import Settings
from fuzzoff.findings import Report
from fuzzoff.report.sanitize import escape_bidi


def _clean(value: Any) -> Any:
    """JSON has no NaN or infinity: write them as null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    return value


def report_dict(report: Report) -> dict[str, Any]:
    return {
        "tool": "fuzzoff",
        "version": __version__,
        "files": [_clean(f.to_json()) for f in report.files],
    }


def render(report: Report, settings: Settings) -> str:
    return escape_bidi(json.dumps(report_dict(report), indent=2, ensure_ascii=False)) + "\n"
