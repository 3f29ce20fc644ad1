"""``--format github``: GitHub Actions workflow commands, one per finding, which the job's log
shows as annotations (and, on a pull request, on its Files tab where the file is in the diff).

``::error`` for an error, ``::warning`` for a warning, ``::notice`` for info, as ruff's
``--output-format github``. The file is the recording's path under the working folder (run
from the repository root), line 1 since a recording is binary; the title names the rule. GitHub
reads ``%``, ``\\r`` and ``\\n`` in a command's message as escapes, and ``:`` and ``,`` in its
properties too (``actions/toolkit``'s ``escapeData`` and ``escapeProperty``): each is written
as its escape, so a recording's text cannot end a command or start another.
"""

from __future__ import annotations

from fuzzoff.config import Settings
from fuzzoff.findings import Report, Severity
from fuzzoff.report.located import Located, located
from fuzzoff.report.sanitize import CI_TEXT_LIMIT, printable

COMMAND = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "notice"}


def escape_data(text: str) -> str:
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def escape_property(text: str) -> str:
    return escape_data(text).replace(":", "%3A").replace(",", "%2C")


def _when(item: Located) -> str:
    f = item.finding
    if f.time_s is None:
        return "whole file"
    return f"{f.time_s:.3f}s" if f.end_s is None else f"{f.time_s:.3f}-{f.end_s:.3f}s"


def command(item: Located) -> str:
    """One workflow command: ``::error file=...,line=1,title=fuzzoff OFB101 (...)::...``."""
    f = item.finding
    vehicle = f" [{f.vehicle}]" if f.vehicle else ""
    where = f"  {f.where}" if f.where is not None and f.where.topic else ""
    text = f"{item.path}: {_when(item)}{vehicle} {f.code} {f.message}{where}"
    properties = {
        "file": item.path,
        "line": "1",
        "title": f"fuzzoff {f.code} ({f.name})",
    }
    props = ",".join(f"{k}={escape_property(printable(v, 500))}" for k, v in properties.items())
    return f"::{COMMAND[f.severity]} {props}::{escape_data(printable(text, CI_TEXT_LIMIT))}"


def render(report: Report, settings: Settings) -> str:
    return "".join(command(item) + "\n" for item in located(report))
