"""The terminal report where it is not a terminal (a pipe, a file, a CI log), without rich.

There the report has no colour, a finding is one line however long and the summary is an ASCII
table: text that plain Python writes as well, without importing rich and building its consoles
(a fifth of a one-file lint's instructions, issue 31). ``plain_report`` writes exactly what
``terminal.print_report`` draws through a console that is not a terminal
(``tests/test_terminal_report.py`` compares the two), and returns None for what it does not draw
itself (``--statistics``, a line that the console's width would wrap): rich draws those.

On a terminal, where ``FORCE_COLOR`` or ``TTY_COMPATIBLE`` is set (either can ask rich for a
terminal's output), in a notebook and on Windows, ``plain_width`` says None and rich draws the
report as before.
"""

from __future__ import annotations

import os
import sys
from collections import Counter

from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.report.sanitize import printable

VERDICT = {0: "passed", 1: "failed", 2: "incomplete input"}

HEAD_WIDTH = 26
"""Columns before a finding's text: time (10), code (6), severity (7) and their spaces."""

FILE_WIDTH = 160
"""The width of the report written to a file (``--output``), as ``render_rich`` sets it."""


def location(finding: Finding, full: bool) -> str:
    """Topic or message type and index (``#140``); ``full`` adds the byte offset (``@10714``)."""
    where = finding.where
    if where is None or not where.topic:
        return ""
    if full:
        return str(where)
    return where.topic if where.index is None else f"{where.topic} #{where.index}"


def plain_width(to_file: bool) -> int | None:
    """The width of the console ``commands._common.render_rich`` would draw the report on
    when that console is not a terminal, or None where it would be one (standard output is a
    terminal, or ``FORCE_COLOR`` or ``TTY_COMPATIBLE`` has a say): rich draws it then."""
    environ = os.environ
    if "TTY_COMPATIBLE" in environ or "FORCE_COLOR" in environ:
        return None
    if "ipykernel" in sys.modules or "IPython" in sys.modules or sys.platform == "win32":
        return None  # a notebook, or a Windows console's width: as rich works them out
    if to_file:
        return FILE_WIDTH
    stream = sys.stdout
    isatty = getattr(stream, "isatty", None)
    try:
        if isatty is None or isatty():
            return None
    except ValueError:  # a closed stream: rich says what it does with it
        return None
    columns = environ.get("COLUMNS")
    if columns is not None:
        return int(columns) if columns.isdigit() and int(columns) > 0 else None
    for fd in (0, 1, 2):  # as rich's Console.size: the first standard stream that is a terminal
        try:
            return os.get_terminal_size(fd).columns or 80
        except (AttributeError, ValueError, OSError):
            continue
    return 80


def _finding_line(finding: Finding, vehicle: bool) -> str:
    when = "whole file" if finding.time_s is None else f"{finding.time_s:.3f}s"
    line = f"{when:>10} {finding.code} {finding.severity.label:<7} "
    if vehicle and finding.vehicle:
        line += f"[{printable(finding.vehicle, 40)}] "
    line += printable(finding.short, 300)
    where = printable(location(finding, full=False), 120)
    return f"{line}  {where}" if where else line


DETAIL_LIMIT = 1000
"""Longest message ``--verbose`` shows (a recording can make one any length; fuzzoff's own
longest, the OFB002 lines, stay under it)."""


def _detail_lines(finding: Finding) -> list[str]:
    # without trailing blanks, which rich 14 and 15 write differently at a line's end
    lines = [printable(finding.message, DETAIL_LIMIT).rstrip()]
    extra = []
    if finding.end_s is not None and finding.time_s is not None:
        extra.append(f"until {finding.end_s:.3f}s")
    where = location(finding, full=True)
    if where:
        extra.append(f"at {printable(where, 120)}")
    if extra:
        lines.append(", ".join(extra))
    return lines


def _header(file: FileReport) -> str:
    about = f"{file.format}, {printable(file.profile.describe(), 200)}"
    vehicles = {f.vehicle for f in file.findings if f.vehicle}
    if len(vehicles) == 1:
        about += f", vehicle {printable(vehicles.pop(), 40)}"
    if not file.complete:
        about += "  (incomplete)"
    return f"{printable(file.path)}  {about}"


class _Wraps(Exception):
    """A line the console's width would wrap: rich draws the report."""


def _short(text: str, width: int) -> str:
    """A line printed without ``soft_wrap``: as is while it fits (ASCII here), else rich."""
    if len(text) > width or not text.isascii():
        raise _Wraps
    return text


def _file(
    out: list[str], file: FileReport, fail_on: Severity, quiet: bool, verbose: bool, width: int
) -> None:
    shown = [f for f in file.findings if not quiet or f.severity >= fail_on]
    if quiet and not shown:
        return
    out.append(_header(file))
    several = len({f.vehicle for f in file.findings if f.vehicle}) > 1
    for finding in shown:
        out.append(_finding_line(finding, several))
        if verbose:
            out.extend(" " * HEAD_WIDTH + line for line in _detail_lines(finding))
    if not shown:
        out.append(_short("  no findings", width))
    if file.suppressed and not quiet:
        kinds = Counter(why.kind for _, why in file.suppressed)
        said = ", ".join(f"{n} by the {kind}" for kind, n in sorted(kinds.items()))
        out.append(_short(f"  {len(file.suppressed)} suppressed ({said})", width))
    if file.delivery is not None and not quiet:
        from fuzzoff.bridge.report import lines

        out.extend(printable(line, 400) for line in lines(file.delivery))
    out.append("")


def _table(title: str, headers: list[str], row: list[str], width: int) -> list[str]:
    """rich's ``Table`` with ``box.ASCII``, ``show_edge=False``, right-justified cells and
    a centred title, as it draws one row that fits the width."""
    widths = [max(len(h), len(c)) + 2 for h, c in zip(headers, row, strict=True)]
    total = sum(widths) + len(widths) - 1
    if total > width or len(title) > total:
        raise _Wraps
    excess = total - len(title)
    left = excess // 2
    lines = [" " * left + title + " " * (excess - left)]
    lines.append("|".join(f" {h:>{w - 2}} " for h, w in zip(headers, widths, strict=True)))
    lines.append("+".join("-" * w for w in widths))
    lines.append("|".join(f" {c:>{w - 2}} " for c, w in zip(row, widths, strict=True)))
    return lines


def summary_row(report: Report) -> tuple[list[str], list[str]]:
    """The summary table's headers and its one row (``suppressed`` only when there are any)."""
    counts = Counter(f.severity for f in report.findings)
    headers = ["files", "errors", "warnings", "info", "unreadable"]
    row = [
        str(len(report.files)),
        str(counts[Severity.ERROR]),
        str(counts[Severity.WARNING]),
        str(counts[Severity.INFO]),
        str(sum(1 for f in report.files if not f.complete)),
    ]
    suppressed = sum(len(f.suppressed) for f in report.files)
    if suppressed:
        headers.append("suppressed")
        row.append(str(suppressed))
    return headers, row


def verdict_text(report: Report, fail_on: Severity, exit_zero: bool) -> tuple[int, str]:
    """The exit status and the summary's ``result:`` text."""
    status = report.exit_status(fail_on)
    verdict = VERDICT[status]
    if status == 1:
        verdict += f" (findings at or above {fail_on.label})"
        if exit_zero:
            verdict += "; exit status 0 (--exit-zero)"
    return status, verdict


HINT = "--verbose shows each finding in full; fuzzoff rule CODE explains a rule, with a fix"


def _summary(
    out: list[str], report: Report, fail_on: Severity, verbose: bool, exit_zero: bool, width: int
) -> None:
    headers, row = summary_row(report)
    out.extend(_table("fuzzoff summary", headers, row, width))
    verdict = verdict_text(report, fail_on, exit_zero)[1]
    out.append(_short(f"result: {verdict}", width))
    if report.findings and not verbose:
        out.append(HINT)


def plain_report(
    report: Report,
    fail_on: Severity,
    width: int,
    *,
    quiet: bool = False,
    statistics: bool = False,
    verbose: bool = False,
    exit_zero: bool = False,
) -> str | None:
    """``terminal.print_report``'s text on a console of ``width`` that is not a terminal, or
    None where rich must draw it (``statistics``, or a line that would wrap)."""
    if statistics:
        return None
    out: list[str] = []
    try:
        for file in report.files:
            _file(out, file, fail_on, quiet, verbose, width)
        if not quiet:
            _summary(out, report, fail_on, verbose, exit_zero, width)
    except _Wraps:
        return None
    return "".join(line + "\n" for line in out)
