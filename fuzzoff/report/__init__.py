"""Renderers: terminal (rich), JSON, SARIF, JUnit and HTML. Machine formats return text."""

from __future__ import annotations

import importlib
from collections.abc import Callable

from fuzzoff.config import Settings
from fuzzoff.findings import Report

Renderer = Callable[[Report, Settings], str]

RENDERERS: dict[str, str] = {
    "json": "fuzzoff.report.json_report:render",
    "sarif": "fuzzoff.report.sarif:render",
    "junit": "fuzzoff.report.junit:render",
    "html": "fuzzoff.report.html:render",
}
"""``--format`` name -> ``module:function`` for the formats written as one text document."""

FORMATS = ("terminal", *RENDERERS)


def renderer(name: str) -> Renderer:
    module_name, _, func = RENDERERS[name].partition(":")
    module = importlib.import_module(module_name)
    render: Renderer = getattr(module, func)
    return render
