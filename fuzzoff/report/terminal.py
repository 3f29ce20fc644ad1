"""Terminal output with rich: findings grouped per file, then a summary (ruff-like).

A finding is one line: its time, code and severity, the key fact (``Finding.short``) and where
in the file it sits; ``--verbose`` adds its whole message (what the docs require and what the
profile's PX4 does), its time window and byte offset, and ``fuzzoff rule CODE`` explains the
rule. On a terminal a line too long for the window wraps at a word, under its own column.

Colour only on a terminal and without ``NO_COLOR`` (rich decides; ``FORCE_COLOR`` forces it);
tables fall back to ASCII when the output is not a terminal. Every string that comes from a
recording goes through ``printable`` and into ``Text`` objects, never into markup, so escape
sequences in a recording are shown as ``\\x1b`` and never reach the terminal.

A fuzz campaign's report is plain text (``render_campaign``), one line per property.
"""

from __future__ import annotations

from collections import Counter
from typing import TYPE_CHECKING

from rich import box
from rich.console import Console
from rich.table import Table
from rich.text import Text

from fuzzoff.catalog import get_rule
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.fuzz.known import KNOWN
from fuzzoff.report import CampaignReport, campaign_seeds
from fuzzoff.report.plain import DETAIL_LIMIT, HEAD_WIDTH, HINT, summary_row, verdict_text
from fuzzoff.report.plain import location as _location
from fuzzoff.report.sanitize import printable

if TYPE_CHECKING:
    from fuzzoff.fuzz.campaign import CampaignResult, PropertyResult

STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "yellow", Severity.INFO: "cyan"}


def table_box(console: Console) -> box.Box:
    """Heavy lines on a terminal; ASCII in a file or a pipe (CI logs, editors)."""
    return box.SIMPLE_HEAVY if console.is_terminal else box.ASCII


def finding_parts(finding: Finding, *, vehicle: bool = True) -> tuple[Text, Text, Text]:
    """The parts of a finding's line: time, code and severity; the key fact (the vehicle
    first where the file has several); where in the file it sits (empty if nowhere)."""
    when = "whole file" if finding.time_s is None else f"{finding.time_s:.3f}s"
    head = Text()
    head.append(f"{when:>10}", style="dim")
    head.append(" ")
    head.append(finding.code, style="bold")
    head.append(" ")
    head.append(f"{finding.severity.label:<7}", style=STYLE[finding.severity])
    body = Text()
    if vehicle and finding.vehicle:
        body.append(f"[{printable(finding.vehicle, 40)}] ", style="magenta")
    body.append(printable(finding.short, 300))
    where = Text(printable(_location(finding, full=False), 120), style="dim")
    return head, body, where


def finding_line(finding: Finding, *, vehicle: bool = True) -> Text:
    """One finding on one line: time, code, severity, the key fact, where."""
    head, body, where = finding_parts(finding, vehicle=vehicle)
    line = Text.assemble(head, " ", body)
    if where:
        line.append("  ").append_text(where)
    return line


def finding_detail(finding: Finding) -> Text:
    """``--verbose``: the whole message, then the time window and the exact place."""
    text = Text(printable(finding.message, DETAIL_LIMIT).rstrip())
    extra = []
    if finding.end_s is not None and finding.time_s is not None:
        extra.append(f"until {finding.end_s:.3f}s")
    location = _location(finding, full=True)
    if location:
        extra.append(f"at {printable(location, 120)}")
    if extra:
        text.append("\n" + ", ".join(extra), style="dim")
    return text


def _print_findings(
    console: Console, findings: list[Finding], vehicle: bool, verbose: bool
) -> None:
    """On a terminal, a grid that wraps long text at word boundaries under its own column; in
    a file or a pipe, one line per finding (grep-able, however long)."""
    if not console.is_terminal:
        for finding in findings:
            console.print(finding_line(finding, vehicle=vehicle), soft_wrap=True)
            if verbose:
                for line in finding_detail(finding).split("\n"):
                    console.print(Text(" " * HEAD_WIDTH).append_text(line), soft_wrap=True)
        return
    grid = Table.grid(padding=(0, 1))
    grid.add_column(no_wrap=True, width=HEAD_WIDTH - 1)
    grid.add_column(overflow="fold")
    room = console.width - HEAD_WIDTH
    for finding in findings:
        head, body, where = finding_parts(finding, vehicle=vehicle)
        if where and body.cell_len + 2 + where.cell_len <= room:
            grid.add_row(head, Text.assemble(body, "  ", where))
        else:  # the place on a row of its own rather than broken across two
            grid.add_row(head, body)
            if where:
                grid.add_row(Text(), where)
        if verbose:
            grid.add_row(Text(), finding_detail(finding))
    console.print(grid)


def file_header_parts(file: FileReport) -> tuple[Text, Text]:
    """The recording's name, and what it is: format, profile, its one vehicle, incomplete."""
    name = Text(printable(file.path), style="bold underline")
    about = Text(f"{file.format}, {printable(file.profile.describe(), 200)}", style="dim")
    vehicles = {f.vehicle for f in file.findings if f.vehicle}
    if len(vehicles) == 1:
        about.append(f", vehicle {printable(vehicles.pop(), 40)}", style="dim")
    if not file.complete:
        about.append("  (incomplete)", style="bold red")
    return name, about


def _print_header(console: Console, file: FileReport) -> None:
    """One line; on a terminal too narrow for it, the name and then what it is, each whole."""
    name, about = file_header_parts(file)
    if not console.is_terminal or name.cell_len + 2 + about.cell_len <= console.width:
        console.print(Text.assemble(name, "  ", about), soft_wrap=True)
        return
    console.print(name, soft_wrap=True)
    console.print(Text("  ").append_text(about))


def print_file(
    console: Console, file: FileReport, fail_on: Severity, quiet: bool, verbose: bool = False
) -> None:
    shown = [f for f in file.findings if not quiet or f.severity >= fail_on]
    if quiet and not shown:
        return
    _print_header(console, file)
    # one vehicle is named in the heading; several are named on each line
    several = len({f.vehicle for f in file.findings if f.vehicle}) > 1
    _print_findings(console, shown, several, verbose)
    if not shown:
        console.print(Text("  no findings", style="green"))
    if file.suppressed and not quiet:
        kinds = Counter(why.kind for _, why in file.suppressed)
        said = ", ".join(f"{n} by the {kind}" for kind, n in sorted(kinds.items()))
        console.print(Text(f"  {len(file.suppressed)} suppressed ({said})", style="dim"))
    if file.delivery is not None and not quiet:
        from fuzzoff.bridge.report import lines

        for line in lines(file.delivery):
            console.print(Text(printable(line, 400)), soft_wrap=True)
    console.print()


def print_summary(
    console: Console,
    report: Report,
    fail_on: Severity,
    verbose: bool = False,
    exit_zero: bool = False,
) -> None:
    headers, row = summary_row(report)
    table = Table(title="fuzzoff summary", box=table_box(console), show_edge=False)
    styles = {"errors": STYLE[Severity.ERROR], "warnings": STYLE[Severity.WARNING]}
    styles.update({"info": STYLE[Severity.INFO], "suppressed": "dim"})
    for header in headers:
        table.add_column(header, justify="right", style=styles.get(header))
    table.add_row(*row)
    console.print(table)
    status, verdict = verdict_text(report, fail_on, exit_zero)
    style = "bold green" if status == 0 else ("bold yellow" if exit_zero else "bold red")
    console.print(Text(f"result: {verdict}", style=style))
    if report.findings and not verbose:
        console.print(Text(HINT, style="dim"), soft_wrap=True)


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
    verbose: bool = False,
    exit_zero: bool = False,
) -> None:
    """The whole terminal report; ``quiet`` keeps only findings at the fail level, no summary;
    ``verbose`` adds each finding's whole message, time window and byte offset."""
    if statistics:
        print_statistics(console, report)
        return
    for file in report.files:
        print_file(console, file, fail_on, quiet, verbose)
    if not quiet:
        print_summary(console, report, fail_on, verbose, exit_zero)


def _property_line(r: PropertyResult) -> str:
    rate = f"{r.examples / r.seconds:.0f}/s" if r.seconds else "-"
    verdict = "FAILED" if r.failed else ("counted" if r.name == "docs-stricter" else "held")
    if not r.examples:
        verdict = "not run"
    return f"  {r.name:<14} {verdict:<8} {r.examples:>6} examples {r.seconds:7.2f} s {rate:>7}"


def render_campaign(campaign: CampaignReport) -> str:
    """``fuzzoff fuzz``'s text: a line per property, its counterexample and what was left out."""
    result, saved = campaign.result, campaign.saved
    margins = campaign.margins
    lines = [f"fuzzoff fuzz, {campaign_seeds(result)}"]
    for problem in result.config.base_problems:
        lines.append(f"  --from incomplete, the part before this was fuzzed: {printable(problem)}")
    for r in result.results:
        lines.append(_property_line(r))
        if r.failed:
            shrunk = f", shrunk in {r.shrinks} steps" if r.shrinks else ""
            lines.append(
                f"      {r.failed_examples} of {r.examples} examples failed; the first "
                f"(example {r.found_after}){shrunk}:"
            )
        for p in r.problems:
            lines.append(f"      {printable(p, 300)}")
        if r.counterexample is not None:
            lines.append(f"      counterexample: {r.counterexample.describe()}")
        if r.name in saved:
            lines.append(f"      reproducer: {saved[r.name]}  (fuzzoff replay {saved[r.name]})")
        for pattern, count in r.known.items():
            what = KNOWN.get(pattern, pattern)
            lines.append(
                f"      left out: a known problem of fuzzoff in {count} examples "
                f"(--include-known to fail on it): {printable(what, 200)}"
            )
        for code, c in r.counts.items():
            lines.append(
                f"      {code}: fired {c['fired']}, gate accepted {c['gate_accepted']} "
                "(docs stricter than code)"
            )
    for m in margins:
        lines.append(f"  margin {m.family:<7} {m.describe()}")
    lines.append(f"{result.examples} examples in {result.seconds:.1f} s; {_verdict(result)}")
    return "\n".join(lines) + "\n"


def _verdict(result: CampaignResult) -> str:
    failed = sum(1 for r in result.results if r.failed)
    verdicts = [f"{failed} propert{'y' if failed == 1 else 'ies'} failed"] if failed else []
    if result.unchecked:
        verdicts.append(f"no example of {', '.join(result.unchecked)} ran")
    return "; ".join(verdicts) or "all held"
