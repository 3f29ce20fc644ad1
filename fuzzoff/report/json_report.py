"""``--format json``: the stable machine-readable shape of spec/interface.md, for a lint and for
a fuzz campaign."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from fuzzoff import __version__
from fuzzoff.config import Settings
from fuzzoff.findings import FileReport, Report
from fuzzoff.report import CampaignReport
from fuzzoff.report.marks import marks
from fuzzoff.report.sanitize import escape_bidi


def clean(value: Any) -> Any:
    """JSON has no NaN or infinity: write them as null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [clean(v) for v in value]
    return value


SCHEMA_FILE = Path(__file__).parent / "schemas" / "lint-report.schema.json"
"""The JSON Schema of this report, shipped in the package (docs/reports.md links it)."""


def file_dict(file: FileReport) -> dict[str, Any]:
    """One recording: ``FileReport.to_json``, each finding with its SARIF fingerprint, and the
    findings a suppression took out (``suppressed``), each with its ``suppression``."""
    data: dict[str, Any] = clean(file.to_json())
    for finding, mark in zip(data["findings"], marks(file.findings), strict=True):
        finding["fingerprint"] = mark
    held = [finding for finding, _ in file.suppressed]
    data["suppressed"] = [
        {**clean(finding.to_json()), "fingerprint": mark, "suppression": why.to_json()}
        for (finding, why), mark in zip(file.suppressed, marks(held), strict=True)
    ]
    return data


def report_dict(report: Report) -> dict[str, Any]:
    return {
        "tool": "fuzzoff",
        "version": __version__,
        "files": [file_dict(f) for f in report.files],
    }


def render(report: Report, settings: Settings) -> str:
    return escape_bidi(json.dumps(report_dict(report), indent=2, ensure_ascii=False)) + "\n"


def render_campaign(campaign: CampaignReport) -> str:
    """``fuzzoff fuzz --format json``: the campaign and each property's result."""
    result, saved = campaign.result, campaign.saved
    margins = campaign.margins
    cfg = result.config
    data: dict[str, Any] = {
        "tool": "fuzzoff",
        "version": __version__,
        "campaign": {
            "px4": cfg.px4,
            "vehicle": cfg.vehicle,
            "transport": cfg.transport,
            "seed": cfg.seed,
            "seeds": list(cfg.seeds) or [cfg.seed],
            "examples": cfg.examples,
            "budget_s": cfg.budget_s,
            "from": None if cfg.base is None else cfg.base.describe(),
            "from_problems": cfg.base_problems,
        },
        "failed": result.failed,
        "unchecked": result.unchecked,
        "examples": result.examples,
        "seconds": round(result.seconds, 3),
        "properties": [],
    }
    for r in result.results:
        entry = r.to_json()
        entry["reproducer"] = str(saved[r.name]) if r.name in saved else None
        data["properties"].append(entry)
    if margins:
        data["margins"] = [m.to_json() for m in margins]
    return json.dumps(data, indent=2) + "\n"
