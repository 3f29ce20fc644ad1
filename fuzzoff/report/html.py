"""``--format html``: one self-contained page that opens offline.

No network request and no script: a Content-Security-Policy forbids both, styles are inline and
the plots are inline SVG (``svg_timeline``). Each rule that has findings is embedded as its page
(``catalog.render_page`` through markdown-it with raw HTML off), so the links work offline.
Everything from a recording (paths, topics, messages, vehicle names) is escaped where it is written.
"""

from __future__ import annotations

from collections import Counter
from html import escape

from markdown_it import MarkdownIt

from fuzzoff import __version__
from fuzzoff.catalog import Rule, get_rule, render_page
from fuzzoff.config import Settings
from fuzzoff.engine import Timeline
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.profiles import SOURCE_WORDS
from fuzzoff.report.html_style import CSS
from fuzzoff.report.sanitize import printable
from fuzzoff.report.svg_timeline import Marker, timeline_svg
from fuzzoff.report.timelines import loss_timeout

CSP = (
    "default-src 'none'; style-src 'unsafe-inline'; img-src data:; "
    "base-uri 'none'; form-action 'none'"
)
"""Forbids every script and every request: the page cannot reach the network even by mistake."""

TEXT_LIMIT = 4000
"""Longest text shown from a recording (a message, a path) before it is cut."""

VERDICT = {0: "passed", 1: "failed", 2: "incomplete input"}


def e(text: object) -> str:
    """Escaped for element text and double-quoted attributes; control characters shown as \\xNN."""
    return escape(printable(str(text), TEXT_LIMIT), quote=True)


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


def _summary(file: FileReport, timelines: dict[str, Timeline]) -> str:
    counts = Counter(f.severity for f in file.findings)
    stats = file.stats
    rows = [
        ("format", e(file.format)),
        ("profile", _profile(file)),
        ("complete", "yes" if file.complete else '<b class="error">no: part could not be read</b>'),
        ("duration", f"{float(stats.get('duration_s') or 0.0):.3f} s"),
        ("events", e(stats.get("events", 0))),
        ("vehicles", e(", ".join(repr(v) for v in timelines) or "none")),
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
    file: FileReport, markers: list[Marker], timelines: dict[str, Timeline], settings: Settings
) -> str:
    if not timelines:
        return '<p class="none">No timeline: the recording has no events fuzzoff could read.</p>'
    stored = file.extras.get("loss_timeouts", {})
    t_end = float(file.stats.get("duration_s") or 0.0)
    vehicles = list(timelines)
    out = []
    for vehicle in vehicles:
        mine = [
            m
            for m in markers
            if m.finding.vehicle == vehicle
            or (m.finding.vehicle not in timelines and vehicle == vehicles[0])
        ]
        tl = timelines[vehicle]
        loss, source = stored.get(vehicle) or loss_timeout(tl, file.profile, settings)
        name = f"vehicle {vehicle!r}" if vehicle else "vehicle (no namespace / id)"
        svg = timeline_svg(
            tl, mine, t_end=t_end, loss_timeout=loss, label=f"{file.path}: {name} timeline"
        )
        out.append(
            f"<figure><figcaption><b>{e(name)}</b>: keep-alive interval with the 500 ms (2 Hz) "
            f"line and the loss timeout COM_OF_LOSS_T = {loss:g} s ({e(source)}); modes and "
            f"setpoint kinds below; a triangle per finding (click it).</figcaption>{svg}</figure>"
        )
    return "".join(out)


COLUMNS = ("time", "rule", "severity", "vehicle", "message", "location")


def _findings_table(markers: list[Marker]) -> str:
    if not markers:
        return '<p class="none">No findings.</p>'
    rows = []
    for m in markers:
        f = m.finding
        rule = _rule(f.code)
        sev = f.severity.label
        when = e(_time(f))
        if f.time_s is not None:
            when = f'<a href="#mark-{e(m.ident)}">{when}</a>'
        code = f'<a href="#rule-{e(f.code)}">{e(f.code)}</a>'
        if rule is not None:
            code += f' <a class="ext" href="{e(rule.url)}" title="rule page online">↗</a>'
        where = e(str(f.where)) if f.where is not None and f.where.topic else ""
        rows.append(
            f'<tr id="finding-{e(m.ident)}" class="{sev}"><td>{when}</td><td>{code}</td>'
            f'<td class="sev {sev}">{sev}</td><td>{e(f.vehicle)}</td><td>{e(f.message)}</td>'
            f"<td><code>{where}</code></td></tr>"
        )
    head = (
        "<tr><th>time</th><th>rule</th><th>severity</th><th>vehicle</th><th>message</th>"
        "<th>location</th></tr>"
    )
    cols = "".join(f'<col class="c-{name}">' for name in COLUMNS)
    return (
        f'<table class="findings"><colgroup>{cols}</colgroup><thead>{head}</thead>'
        f"<tbody>{''.join(rows)}</tbody></table>"
    )


def _file_section(index: int, file: FileReport, settings: Settings) -> str:
    timelines: dict[str, Timeline] = file.extras.get("timelines", {})
    markers = [Marker(f"{index}-{i}", f) for i, f in enumerate(file.findings)]
    return (
        f'<section class="file" id="file-{index}"><h2>{e(file.path)}</h2>'
        f"{_summary(file, timelines)}<h3>Timeline</h3>"
        f"{_plots(file, markers, timelines, settings)}"
        f"<h3>Findings</h3>{_findings_table(markers)}</section>"
    )


_MARKDOWN = MarkdownIt("commonmark", {"html": False})


def rule_article(rule: Rule) -> str:
    """The rule page (trusted catalog text, rendered with raw HTML disabled all the same)."""
    body = _MARKDOWN.render(render_page(rule))
    body = body.replace("<h2>", "<h4>").replace("</h2>", "</h4>")
    body = body.replace("<h1>", "<h3>").replace("</h1>", "</h3>")
    return (
        f'<article class="rule" id="rule-{e(rule.code)}">{body}'
        f'<p>Online: <a href="{e(rule.url)}">{e(rule.url)}</a></p></article>'
    )


def _contents(report: Report, fail_on: Severity) -> str:
    items = []
    for i, file in enumerate(report.files):
        worst = file.worst()
        css = worst.label if worst is not None else "ok"
        label = worst.label if worst is not None else "no findings"
        items.append(
            f'<li><a href="#file-{i}">{e(file.path)}</a> <span class="sev {css}">{label}</span> '
            f"({len(file.findings)} findings)</li>"
        )
    if not report.files:
        return '<p class="none">No recordings were found in the paths given.</p>'
    status = report.exit_status(fail_on)
    total = Counter(f.severity for f in report.findings)
    return (
        f'<p class="verdict v{status}">Result: {VERDICT[status]} (fail level {fail_on.label}); '
        f"{len(report.files)} recordings, {total[Severity.ERROR]} errors, "
        f"{total[Severity.WARNING]} warnings, {total[Severity.INFO]} info.</p>"
        f'<ol class="contents">{"".join(items)}</ol>'
    )


def render(report: Report, settings: Settings) -> str:
    sections = "".join(_file_section(i, f, settings) for i, f in enumerate(report.files))
    codes = sorted({f.code for f in report.findings})
    rules = [r for r in (_rule(c) for c in codes) if r is not None]
    articles = "".join(rule_article(r) for r in rules)
    rules_section = f'<section id="rules"><h2>Rules</h2>{articles}</section>' if rules else ""
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>fuzzoff report</title><style>{CSS}</style></head><body>"
        f"<header><h1>fuzzoff report</h1><p>fuzzoff {e(__version__)}</p></header>"
        f"<main>{_contents(report, settings.fail_on)}{sections}{rules_section}</main>"
        "</body></html>\n"
    )
