"""Terminal output with rich: findings grouped per file, then a summary (ruff-like).

Colour only on a terminal and without ``NO_COLOR`` (rich decides; ``FORCE_COLOR`` forces it);
tables fall back to ASCII when the output is not a terminal. Every string that comes from a
recording goes through ``printable`` and into ``Text`` objects, never into markup, so escape
sequences in a recording are shown as ``\\x1b`` and never reach the terminal.
"""

from __future__ import annotations

from collections import Counter

from rich import box
from rich.console import Console
from rich.progress import BarColumn, Progress, TaskID, TextColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text

from fuzzoff.catalog import get_rule
from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.report.sanitize import printable
from fuzzoff.sources import recordings_in

STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "yellow", Severity.INFO: "cyan"}
VERDICT = {0: "passed", 1: "failed", 2: "incomplete input"}


def table_box(console: Console) -> box.Box:
    """Heavy lines on a terminal; ASCII in a file or a pipe (CI logs, editors)."""
    return box.SIMPLE_HEAVY if console.is_terminal else box.ASCII


def finding_line(finding: Finding) -> Text:
    when = "   whole file" if finding.time_s is None else f"{finding.time_s:11.3f}s"
    line = Text()
    line.append(when, style="dim")
    line.append("  ")
    line.append(finding.code, style="bold")
    line.append(" ")
    line.append(f"{finding.severity.label:<7}", style=STYLE[finding.severity])
    line.append(" ")
    if finding.vehicle:
        line.append(f"[{printable(finding.vehicle, 40)}] ", style="magenta")
    line.append(printable(finding.message))
    if finding.end_s is not None and finding.time_s is not None:
        line.append(f"  (until {finding.end_s:.3f}s)", style="dim")
    if finding.where is not None and finding.where.topic:
        line.append(f"  at {printable(str(finding.where), 120)}", style="dim")
    return line


def file_header(file: FileReport) -> Text:
    header = Text()
    header.append(printable(file.path), style="bold underline")
    header.append(f"  {file.format}, {printable(file.profile.describe(), 200)}", style="dim")
    if not file.complete:
        header.append("  (incomplete)", style="bold red")
    return header


def print_file(console: Console, file: FileReport, fail_on: Severity, quiet: bool) -> None:
    shown = [f for f in file.findings if not quiet or f.severity >= fail_on]
    if quiet and not shown:
        return
    console.print(file_header(file), soft_wrap=True)
    for finding in shown:
        console.print(finding_line(finding), soft_wrap=True)
    if not shown:
        console.print(Text("  no findings", style="green"))
    console.print()


def print_summary(console: Console, report: Report, fail_on: Severity) -> None:
    counts = Counter(f.severity for f in report.findings)
    table = Table(title="fuzzoff summary", box=table_box(console), show_edge=False)
    table.add_column("files", justify="right")
    table.add_column("errors", justify="right", style=STYLE[Severity.ERROR])
    table.add_column("warnings", justify="right", style=STYLE[Severity.WARNING])
    table.add_column("info", justify="right", style=STYLE[Severity.INFO])
    table.add_column("unreadable", justify="right")
    table.add_row(
        str(len(report.files)),
        str(counts[Severity.ERROR]),
        str(counts[Severity.WARNING]),
        str(counts[Severity.INFO]),
        str(sum(1 for f in report.files if not f.complete)),
    )
    console.print(table)
    status = report.exit_status(fail_on)
    verdict = VERDICT[status]
    if status == 1:
        verdict += f" (findings at or above {fail_on.label})"
    style = "bold green" if status == 0 else "bold red"
    console.print(Text(f"result: {verdict}", style=style))


def print_statistics(console: Console, report: Report) -> None:
    """Counts per rule, most frequent first (``ruff --statistics``)."""
    counts = Counter(f.code for f in report.findings)
    worst: dict[str, Severity] = {}
    for f in report.findings:
        worst[f.code] = max(f.severity, worst.get(f.code, f.severity))
    if not counts:
        console.print(Text("no findings", style="green"))
        return
    table = Table(box=None, show_header=False, pad_edge=False)
    table.add_column("count", justify="right")
    table.add_column("code", style="bold")
    table.add_column("severity")
    table.add_column("name")
    for code, count in sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])):
        sev = worst[code]
        table.add_row(str(count), code, Text(sev.label, style=STYLE[sev]), get_rule(code).name)
    console.print(table)


def print_report(
    console: Console,
    report: Report,
    fail_on: Severity,
    *,
    quiet: bool = False,
    statistics: bool = False,
) -> None:
    """The whole terminal report; ``quiet`` keeps only findings at the fail level, no summary."""
    if statistics:
        print_statistics(console, report)
        return
    for file in report.files:
        print_file(console, file, fail_on, quiet)
    if not quiet:
        print_summary(console, report, fail_on)


def lint_with_progress(paths: list[str], settings: Settings, console: Console) -> Report:
    """One file at a time with a progress bar on the terminal (long files take seconds)."""
    report = Report()
    files = recordings_in(paths)
    columns = (TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        for f in files:
            task = progress.add_task(printable(f.name, 60), total=1.0)

            def advance(fraction: float, task: TaskID = task) -> None:
                progress.update(task, completed=fraction)

            report.files.append(lint_file(f, settings, progress=advance))
            progress.remove_task(task)
    return report
