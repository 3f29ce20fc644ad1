"""Renderers: terminal (rich), JSON, SARIF, JUnit, HTML, GitHub workflow commands, reviewdog's
rdjson, GitLab Code Quality and JSON lines. Machine formats return text.

One module per format writes both what ``fuzzoff lint`` reports (a ``Report``) and what
``fuzzoff fuzz`` reports (a ``CampaignReport``); a renderer only renders: the commands run the
lint or the campaign and hand it the result.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from fuzzoff.config import Settings
from fuzzoff.findings import Report
from fuzzoff.lean_dataclass import dataclass

if TYPE_CHECKING:  # the fuzz extra (Hypothesis) is not needed to lint
    from fuzzoff.fuzz.campaign import CampaignResult
    from fuzzoff.fuzz.mutate import Margin

Renderer = Callable[[Report, Settings], str]

RENDERERS: dict[str, str] = {
    "json": "fuzzoff.report.json_report:render",
    "sarif": "fuzzoff.report.sarif:render",
    "junit": "fuzzoff.report.junit:render",
    "html": "fuzzoff.report.html:render",
    "github": "fuzzoff.report.github:render",
    "rdjson": "fuzzoff.report.rdjson:render",
    "gitlab": "fuzzoff.report.gitlab:render",
    "json-lines": "fuzzoff.report.json_lines:render",
}
"""``--format`` name -> ``module:function`` for the formats written as one text document."""

FORMATS = ("terminal", *RENDERERS)


def renderer(name: str) -> Renderer:
    module_name, _, func = RENDERERS[name].partition(":")
    module = importlib.import_module(module_name)
    render: Renderer = getattr(module, func)
    return render


@dataclass(frozen=True, slots=True)
class CampaignReport:
    """What ``fuzzoff fuzz`` reports: the campaign's result, the reproducers saved (by
    property) and, for ``--from``, the margins of the recording."""

    result: CampaignResult
    saved: dict[str, Path]
    margins: list[Margin]


CampaignRenderer = Callable[[CampaignReport], str]

CAMPAIGN_RENDERERS: dict[str, str] = {
    "terminal": "fuzzoff.report.terminal:render_campaign",
    "json": "fuzzoff.report.json_report:render_campaign",
    "junit": "fuzzoff.report.junit:render_campaign",
    "sarif": "fuzzoff.report.sarif:render_campaign",
}
"""``fuzzoff fuzz --format`` name -> ``module:function``."""


def campaign_renderer(name: str) -> CampaignRenderer:
    module_name, _, func = CAMPAIGN_RENDERERS[name].partition(":")
    module = importlib.import_module(module_name)
    render: CampaignRenderer = getattr(module, func)
    return render


def campaign_seeds(result: CampaignResult) -> str:
    """``seed 3``, or ``seeds 0-199 (200 campaigns)`` for a merged run."""
    seeds = result.config.seeds
    if len(seeds) > 1:
        return f"seeds {seeds_text(seeds)} ({len(seeds)} campaigns)"
    return f"seed {result.config.seed}"


def seeds_text(seeds: tuple[int, ...]) -> str:
    """``0-199`` for a range, else the seeds with commas."""
    if seeds == tuple(range(seeds[0], seeds[0] + len(seeds))):
        return f"{seeds[0]}-{seeds[-1]}"
    return ",".join(str(s) for s in seeds)
