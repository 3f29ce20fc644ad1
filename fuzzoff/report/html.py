"""``--format html``: one self-contained page that opens offline.

An index of the recordings (sortable, filterable by severity, rule and name), then per recording
a summary, a zoomable timeline per vehicle (``html_plot`` builds the data, ``timeline.js`` draws
it with uPlot, both inline) and the findings table, then the page of every rule that has
findings (``catalog.render_page`` through markdown-it with raw HTML off), so the links work
offline. The page fetches nothing and runs only its own two scripts (``html_assets``).
Everything from a recording (paths, topics, messages, vehicle names, status texts) is escaped
where it is written into markup, or travels as escaped JSON that the script puts on the page
as text.
"""

from __future__ import annotations

import datetime
from collections import Counter
from html import escape
from pathlib import Path

from markdown_it import MarkdownIt

from fuzzoff import __version__
from fuzzoff.bridge.changes import LATE_S
from fuzzoff.catalog import Rule, get_rule, render_page
from fuzzoff.config import Settings
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.profiles import SOURCE_WORDS
from fuzzoff.report.html_assets import CSP, report_csp, scripts, uplot_css
from fuzzoff.report.html_plot import Marker, as_script_data, loss_line, vehicle_plot
from fuzzoff.report.html_style import CSS
from fuzzoff.report.sanitize import printable
from fuzzoff.timeline import Timeline

__all__ = ["CSP", "e", "render", "rule_article"]

TEXT_LIMIT = 4000
"""Longest text shown from a recording (a message, a path) before it is cut."""

VERDICT = {0: "passed", 1: "failed", 2: "incomplete input"}


def e(text: object) -> str:
    """Escaped for element text and double-quoted attributes; control characters shown as \\xNN."""
    return escape(printable(str(text), TEXT_LIMIT), quote=True)


def vehicle_name(vehicle: str) -> str:
    """A vehicle as a reader names it: its MAVLink system id or ROS namespace, as it is."""
    return f"vehicle {vehicle}" if vehicle else "vehicle (no namespace / id)"


def _rule(code: str) -> Rule | None:
    try:
        return get_rule(code)
    except KeyError:
        return None


def _time(finding: Finding) -> str:
    if finding.time_s is None:
        return "whole file"
    text = f"{finding.time_s:.3f} s"
    if finding.end_s is not None:
        text += f" – {finding.end_s:.3f} s"
    return text


def _profile(file: FileReport) -> str:
    p = file.profile
    release = f" (release {e(p.px4_release)})" if p.px4_release else ""
    px4 = SOURCE_WORDS[p.px4_source]
    vehicle = SOURCE_WORDS[p.vehicle_source]
    return f"PX4 <b>{e(p.px4)}</b>{release}, {px4}; vehicle <b>{e(p.vehicle)}</b>, {vehicle}"


def start_text(file: FileReport) -> str:
    """The recording's start on the wall clock, in UTC, or why it is not known."""
    start = file.stats.get("start_unix_s")
    if not isinstance(start, int | float):
        return "not in the recording (its clock counts from boot or simulation start)"
    moment = datetime.datetime.fromtimestamp(start, datetime.UTC)
    return moment.strftime("%Y-%m-%d %H:%M:%S.%f")[:-3] + " UTC"


def _summary(file: FileReport, timelines: dict[str, Timeline]) -> str:
    counts = Counter(f.severity for f in file.findings)
    stats = file.stats
    vehicles = ", ".join(vehicle_name(v).removeprefix("vehicle ") for v in timelines)
    rows = [
        ("format", e(file.format)),
        ("profile", _profile(file)),
        ("complete", "yes" if file.complete else '<b class="error">no: part could not be read</b>'),
        ("start", e(start_text(file))),
        ("duration", f"{float(stats.get('duration_s') or 0.0):.3f} s"),
        ("events", e(stats.get("events", 0))),
        ("vehicles", e(vehicles or "none")),
        (
            "findings",
            f'<span class="error">{counts[Severity.ERROR]} error</span>, '
            f'<span class="warning">{counts[Severity.WARNING]} warning</span>, '
            f'<span class="info">{counts[Severity.INFO]} info</span>',
        ),
    ]
    items = "".join(f"<dt>{name}</dt><dd>{value}</dd>" for name, value in rows)
    out = f'<dl class="summary">{items}</dl>'
    if file.problems:
        out += '<ul class="problems">' + "".join(f"<li>{e(p)}</li>" for p in file.problems)
        out += "</ul>"
    return out


def _plots(
    index: int,
    file: FileReport,
    markers: list[Marker],
    timelines: dict[str, Timeline],
) -> str:
    if not timelines:
        return '<p class="none">No timeline: the recording has no events fuzzoff could read.</p>'
    t_end = float(file.stats.get("duration_s") or 0.0)
    start = file.stats.get("start_unix_s")
    vehicles = list(timelines)
    out = []
    for k, vehicle in enumerate(vehicles):
        mine = [
            m
            for m in markers
            if m.finding.vehicle == vehicle
            or (m.finding.vehicle not in timelines and vehicle == vehicles[0])
        ]
        tl = timelines[vehicle]
        seconds, source = file.loss_timeouts[vehicle]
        recorded = tl.recorded_params.get("COM_OF_LOSS_T")
        loss = loss_line(seconds, source, file.profile, recorded)
        name = vehicle_name(vehicle)
        data = vehicle_plot(tl, mine, t_end=t_end, loss=loss, name=name)
        ident = f"plot-{index}-{k}"
        marks = " ".join(m.ident for m in mine if m.finding.time_s is not None)
        start_attr = f' data-start="{start!r}"' if isinstance(start, int | float) else ""
        out.append(
            f'<figure class="timeline" tabindex="0" data-plot="{ident}" data-marks="{e(marks)}"'
            f'{start_attr} aria-label="{e(file.path)}: {e(name)} timeline">'
            f"<figcaption><b>{e(name)}</b>: {e(loss.caption)}.</figcaption>"
            '<p class="needs-js none">The timeline is drawn by the report\'s own script, '
            "which this viewer did not run; the findings below do not need it.</p>"
            f'<script type="application/json" id="{ident}">{as_script_data(data)}</script>'
            "</figure>"
        )
    return "".join(out)


COLUMNS = ("time", "rule", "severity", "vehicle", "message", "location")


def _findings_table(markers: list[Marker], timed: set[str]) -> str:
    if not markers:
        return '<p class="none">No findings.</p>'
    rows = []
    for m in markers:
        f = m.finding
        sev = f.severity.label
        when = e(_time(f))
        if m.ident in timed:
            when = f'<a href="#mark-{e(m.ident)}">{when}</a>'
        code = f'<a href="#rule-{e(f.code)}">{e(f.code)}</a>'
        where = e(str(f.where)) if f.where is not None and f.where.topic else ""
        rows.append(
            f'<tr id="finding-{e(m.ident)}" class="{sev}"><td>{when}</td><td>{code}</td>'
            f'<td class="sev {sev}">{sev}</td><td>{e(f.vehicle)}</td><td>{e(f.message)}</td>'
            f"<td><code>{where}</code></td></tr>"
        )
    head = "".join(f"<th>{name}</th>" for name in COLUMNS)
    cols = "".join(f'<col class="c-{name}">' for name in COLUMNS)
    return (
        f'<table class="findings"><colgroup>{cols}</colgroup><thead><tr>{head}</tr></thead>'
        f"<tbody>{''.join(rows)}</tbody></table>"
    )


SUPPRESSED_COLUMNS = ("time", "rule", "severity", "vehicle", "message", "suppressed by")


def _suppressed_table(file: FileReport) -> str:
    """The findings a suppression took out (issue 30): shown, never dropped silently."""
    if not file.suppressed:
        return ""
    rows = []
    for f, why in file.suppressed:
        sev = f.severity.label
        by = f"{why.kind} ({Path(why.source).name}): {why.reason}"
        if why.from_s is not None or why.to_s is not None:
            low = "start" if why.from_s is None else f"{why.from_s:g} s"
            high = "end" if why.to_s is None else f"{why.to_s:g} s"
            by += f", {low} to {high}"
        rows.append(
            f'<tr class="suppressed"><td>{e(_time(f))}</td>'
            f'<td><a href="#rule-{e(f.code)}">{e(f.code)}</a></td><td class="sev">{sev}</td>'
            f"<td>{e(f.vehicle)}</td><td>{e(f.message)}</td><td>{e(by)}</td></tr>"
        )
    head = "".join(f"<th>{name}</th>" for name in SUPPRESSED_COLUMNS)
    return (
        f"<h3>Suppressed ({len(file.suppressed)})</h3>"
        '<p class="none">Findings the configuration\'s <code>suppressions</code> or the '
        "<code>--baseline</code> took out: they fail no run.</p>"
        f'<table class="findings suppressed"><thead><tr>{head}</tr></thead>'
        f"<tbody>{''.join(rows)}</tbody></table>"
    )


DELIVERY_COLUMNS = (
    "topic",
    "direction",
    "in the bag",
    "in PX4's log",
    "never received",
    "latency median",
    "latency max",
    "note",
)


def _times(n: int) -> str:
    return "once" if n == 1 else f"{n} times"


def _ms(value: float | None) -> str:
    return "" if value is None else f"{value:.1f} ms"


def _delivery_section(file: FileReport) -> str:
    """``lint BAG --with ULOG``: per topic what was sent and what arrived (both ways), and
    PX4's status changes the companion saw late or never (``fuzzoff.bridge``)."""
    delivery = file.delivery
    if delivery is None:
        return ""
    clock = delivery.clock
    source = (
        f"{clock.pairs} of PX4's outputs, within {clock.residual_us / 1000:.1f} ms"
        if clock.pairs
        else "the bridge's time sync offset alone (the bag holds no PX4 output)"
    )
    rows = []
    for topic in delivery.topics:
        to_px4 = topic.direction == "in"
        median, worst = (None, None) if topic.latency_ms is None else topic.latency_ms[:2]
        never = topic.undelivered if to_px4 else len(topic.windows)
        cls = ' class="undelivered"' if never else ""
        notes = (
            []
            if to_px4
            else [
                f"none reached the companion {w.start_s:.2f}-{w.end_s:.2f} s" for w in topic.windows
            ]
        )
        notes += [topic.note] if topic.note else []
        rows.append(
            f"<tr{cls}><td>{e(topic.topic)}</td>"
            f"<td>{'to PX4' if to_px4 else 'from PX4'}</td>"
            f"<td>{topic.recorded}</td><td>{topic.logged}</td>"
            f"<td>{never if to_px4 else ''}</td>"
            f"<td>{_ms(median)}</td><td>{_ms(worst)}</td><td>{e('; '.join(notes))}</td></tr>"
        )
    head = "".join(f"<th>{name}</th>" for name in DELIVERY_COLUMNS)
    unseen = [c for c in delivery.changes if c.seen_after_s is None]
    losses = [c for c in delivery.changes if c.lost_signal]
    missed = [c for c in losses if c.seen_after_s is None]
    late = [c for c in losses if c.seen_after_s is not None and c.seen_after_s >= LATE_S]
    changes = []
    for change in delivery.changes:
        seen = "never" if change.seen_after_s is None else f"{change.seen_after_s:.2f} s later"
        cls = ' class="undelivered"' if change.seen_after_s is None else ""
        changes.append(
            f"<tr{cls}><td>{change.px4_s:.2f} s</td><td>{change.time_s:.2f} s</td>"
            f"<td>{e(change.what)}</td><td>{e(seen)}</td></tr>"
        )
    note = f"<p>PX4's status: {e(delivery.changes_note)}</p>" if delivery.changes_note else ""
    return (
        "<h3>Sent against received</h3>"
        f"<p>With PX4's ULog {e(delivery.ulog)}: PX4's clock runs at {clock.rate:.3f} of the"
        f" host's, measured by {e(source)}. PX4 flagged the offboard signal lost"
        f" {_times(len(losses))}; of those losses the companion never saw {len(missed)} and saw"
        f" {len(late)} only {LATE_S:g} s or more later. {len(unseen)} of PX4's"
        f" {len(delivery.changes)} status changes never reached it.</p>"
        f'<table class="findings delivery"><thead><tr>{head}</tr></thead>'
        f"<tbody>{''.join(rows)}</tbody></table>"
        '<table class="findings delivery-changes"><thead><tr><th>PX4 time</th>'
        "<th>bag time</th><th>PX4's status</th><th>the companion saw it</th></tr></thead>"
        f"<tbody>{''.join(changes)}</tbody></table>{note}"
    )


def _file_section(index: int, file: FileReport) -> str:
    timelines = file.timelines
    markers = [Marker(f"{index}-{i}", f) for i, f in enumerate(file.findings)]
    timed = {m.ident for m in markers if m.finding.time_s is not None and timelines}
    return (
        f'<section class="file" id="file-{index}"><h2>{e(file.path)}</h2>'
        f"{_summary(file, timelines)}<h3>Timeline</h3>"
        f"{_plots(index, file, markers, timelines)}"
        f"<h3>Findings</h3>{_findings_table(markers, timed)}{_suppressed_table(file)}"
        f"{_delivery_section(file)}</section>"
    )


_MARKDOWN = MarkdownIt("commonmark", {"html": False})


def rule_article(rule: Rule) -> str:
    """The rule page (trusted catalog text, rendered with raw HTML disabled all the same)."""
    body = _MARKDOWN.render(render_page(rule))
    body = body.replace("<h2>", "<h4>").replace("</h2>", "</h4>")
    body = body.replace("<h1>", "<h3>").replace("</h1>", "</h3>")
    return (
        f'<article class="rule" id="rule-{e(rule.code)}">{body}'
        f"<p>In a terminal: <code>fuzzoff rule {e(rule.code)}</code>; in fuzzoff's repository: "
        f"<code>{e(rule.page)}</code>.</p></article>"
    )


INDEX_COLUMNS = (
    ("recording", "text"),
    ("format", "text"),
    ("PX4", "text"),
    ("vehicle", "text"),
    ("duration s", "number"),
    ("errors", "number"),
    ("warnings", "number"),
    ("info", "number"),
    ("rules", "text"),
    ("read", "text"),
)


def _index_row(i: int, file: FileReport) -> str:
    worst = file.worst()
    counts = Counter(f.severity for f in file.findings)
    codes = sorted({f.code for f in file.findings})
    duration = float(file.stats.get("duration_s") or 0.0)
    label = worst.label if worst is not None else "none"
    cells = [
        f'<a href="#file-{i}">{e(file.path)}</a>',
        e(file.format),
        e(file.profile.px4),
        e(file.profile.vehicle),
        f"{duration:.1f}",
        str(counts[Severity.ERROR]),
        str(counts[Severity.WARNING]),
        str(counts[Severity.INFO]),
        " ".join(f'<a href="#rule-{e(c)}">{e(c)}</a>' for c in codes),
        "yes" if file.complete else '<b class="error">no</b>',
    ]
    sort_keys = {4: f"{duration:.6f}"}
    tds = "".join(
        f'<td data-sort="{sort_keys[k]}">{cell}</td>' if k in sort_keys else f"<td>{cell}</td>"
        for k, cell in enumerate(cells)
    )
    return (
        f'<tr class="sev-{label}" data-file="file-{i}" data-worst="{label}" '
        f'data-rules="{e(" ".join(codes))}" data-path="{e(file.path)}">{tds}</tr>'
    )


def _index(report: Report, fail_on: Severity) -> str:
    if not report.files:
        return '<p class="none">No recordings were found in the paths given.</p>'
    status = report.exit_status(fail_on)
    total = Counter(f.severity for f in report.findings)
    verdict = (
        f'<p class="verdict v{status}">Result: {VERDICT[status]} (fail level {fail_on.label}); '
        f"{len(report.files)} recordings, {total[Severity.ERROR]} errors, "
        f"{total[Severity.WARNING]} warnings, {total[Severity.INFO]} info.</p>"
    )
    codes = sorted({f.code for f in report.findings})
    options = "".join(f'<option value="{e(c)}">{e(c)}</option>' for c in codes)
    controls = (
        '<div class="index-controls" hidden>'
        '<label>severity <select name="severity"><option value="">any</option>'
        '<option value="error">with errors</option>'
        '<option value="warning">warnings or worse</option>'
        '<option value="info">any finding</option>'
        '<option value="none">no findings</option></select></label>'
        f'<label>rule <select name="rule"><option value="">any</option>{options}</select></label>'
        '<label>name <input name="text" type="search" placeholder="part of the path"></label>'
        '<span class="count"></span></div>'
    )
    head = "".join(
        f'<th data-type="{kind}"><button type="button" title="sort">{name}</button></th>'
        for name, kind in INDEX_COLUMNS
    )
    rows = "".join(_index_row(i, f) for i, f in enumerate(report.files))
    return (
        f"{verdict}{controls}"
        f'<div class="index-wrap"><table class="index"><thead><tr>{head}</tr></thead>'
        f"<tbody>{rows}</tbody></table></div>"
    )


HELP = (
    '<details class="help"><summary>Reading a timeline</summary><p>Per vehicle, top to bottom: '
    "a marker per finding (a number is a group of findings too close to tell apart: click it "
    "to zoom in); the time since the previous keep-alive message, on a log axis, with the "
    "500 ms (2 Hz) line of the docs and the loss-timeout line of the PX4 version (during a gap "
    "the line rises as the newest keep-alive ages); the vehicle's position beside the position "
    "setpoints, where the recording has them; bands for the offboard signal as the gate model "
    "holds it, the recorded mode (paler while disarmed), the mode the model predicts, and each "
    "kind of setpoint sent; then PX4's text messages (failsafe ones marked) and the commands "
    "with their acks. Drag across a plot to zoom in, Ctrl + wheel to zoom, Shift + wheel or "
    "the arrows to move, double-click for the whole recording; the plots of a vehicle move "
    "together. Times count from the recording's first message.</p></details>"
)


def render(report: Report, settings: Settings) -> str:
    sections = "".join(_file_section(i, f) for i, f in enumerate(report.files))
    codes = sorted(
        {f.code for f in report.findings} | {f.code for x in report.files for f, _ in x.suppressed}
    )
    rules = [r for r in (_rule(c) for c in codes) if r is not None]
    articles = "".join(rule_article(r) for r in rules)
    rules_section = f'<section id="rules"><h2>Rules</h2>{articles}</section>' if rules else ""
    uplot, app = scripts()
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        f'<meta http-equiv="Content-Security-Policy" content="{report_csp()}">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>fuzzoff report</title><style>{uplot_css()}{CSS}</style></head><body>"
        f"<header><h1>fuzzoff report</h1><p>fuzzoff {e(__version__)}</p></header>"
        f"<main>{_index(report, settings.fail_on)}{HELP}{sections}{rules_section}</main>"
        f"<script>{uplot}</script><script>{app}</script>"
        "</body></html>\n"
    )
