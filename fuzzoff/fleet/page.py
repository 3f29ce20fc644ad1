"""``fuzzoff fleet DIR``: one self-contained HTML page over the fleet table.

What a fleet's team asks of a night's lint: which rules fire, how often per week (is it getting
better?), on which PX4 releases and vehicle types, which flights are the worst (with a link to
each one's own report), and what changed since the run before. Shares are of recordings (a
rule that fires 400 times in one flight counts once), so weeks with more flights compare fairly.

Like the lint's HTML report: no script, no request (the same Content-Security-Policy and
style sheet), and every text that came from a recording or a path is escaped where written.
Each recording counts once, with its newest row (a ``--force`` run supersedes older ones).
"""

from __future__ import annotations

import hashlib
from dataclasses import field
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc

from fuzzoff import __version__
from fuzzoff.catalog import get_rule
from fuzzoff.fleet.dataset import FINDINGS, RECORDINGS, latest, read
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.report.html import CSP, e
from fuzzoff.report.html_style import CSS

WEEKS = 12
"""Weeks shown in the per-week table (the newest)."""

EXTRA_CSS = """
table.grid { border-collapse: collapse; margin: 6px 0 18px; background: #fff; }
table.grid th, table.grid td { border: 1px solid #ddd; padding: 3px 8px; text-align: right;
  white-space: nowrap; }
table.grid th.l, table.grid td.l { text-align: left; white-space: normal; }
table.grid td.z { color: #bbb; } table.grid td.up { color: var(--error); font-weight: 600; }
table.grid td.down { color: var(--ok); font-weight: 600; }
table.grid td.path { text-align: left; word-break: break-all; white-space: normal; }
p.note { color: #555; margin: 2px 0 8px; }
"""


@dataclass(slots=True)
class Fleet:
    """The newest row of every recording and the findings of those rows; and every row of
    every run (``history``), for the comparison of two runs."""

    recordings: pa.Table
    findings: pa.Table
    history: pa.Table
    history_findings: pa.Table
    runs: list[str] = field(default_factory=list)

    @classmethod
    def load(cls, root: Path) -> Fleet:
        every = _with_week(_keyed(read(root, RECORDINGS)))
        every_finding = _with_week(_keyed(read(root, FINDINGS)))
        recordings = latest(every, "key")
        findings = every_finding.join(
            recordings.select(["key", "run_id"]), keys=["key", "run_id"], join_type="inner"
        )
        runs = sorted(set(every.column("run_id").to_pylist()))
        return cls(recordings, findings, every, every_finding, runs)


def _keyed(table: pa.Table) -> pa.Table:
    """A recording's key: its content hash, or its path where it has none (a URL that could
    not be fetched)."""
    path_key = pc.binary_join_element_wise("path:", table.column("path"), "")
    return table.append_column("key", pc.coalesce(table.column("sha256"), path_key))


def _with_week(table: pa.Table) -> pa.Table:
    """The ISO week of the flight (its start time), else of the run that linted it."""
    when = pc.coalesce(
        table.column("start_time"), pc.cast(table.column("run_date"), pa.timestamp("us", "UTC"))
    )
    year = pc.cast(pc.iso_year(when), pa.string())
    week = pc.utf8_lpad(pc.cast(pc.iso_week(when), pa.string()), 2, "0")
    return table.append_column("week", pc.binary_join_element_wise(year, week, "-W"))


def _label(table: pa.Table, column: str) -> pa.Table:
    """Null groups shown as ``unknown`` (a recording that names no release)."""
    filled = pc.fill_null(table.column(column), "unknown")
    return table.set_column(table.schema.get_field_index(column), column, filled)


@dataclass(slots=True)
class Crosstab:
    """Per rule and column value: recordings in which the rule fired, of all recordings."""

    columns: list[str]
    totals: dict[str, int]
    hits: dict[tuple[str, str], int]
    codes: list[str]


def crosstab(fleet: Fleet, column: str, keep: list[str] | None = None) -> Crosstab:
    """Over each recording's newest row, except per run (``run_id``): over every row."""
    history = column == "run_id"
    recordings = _label(fleet.history if history else fleet.recordings, column)
    findings = _label(fleet.history_findings if history else fleet.findings, column)
    totals = {
        str(row[column]): int(row["key_count"])
        for row in recordings.group_by([column]).aggregate([("key", "count")]).to_pylist()
    }
    hits: dict[tuple[str, str], int] = {}
    if findings.num_rows:
        grouped = findings.group_by(["code", column]).aggregate([("key", "count_distinct")])
        for row in grouped.to_pylist():
            hits[(str(row["code"]), str(row[column]))] = int(row["key_count_distinct"])
    columns = keep if keep is not None else sorted(totals)
    codes = sorted(
        {code for code, value in hits if value in columns},
        key=lambda c: (-sum(hits.get((c, v), 0) for v in columns), c),
    )
    return Crosstab(columns, totals, hits, codes)


def _rule_cell(code: str) -> str:
    try:
        name = get_rule(code).name
    except KeyError:
        name = ""
    return f'<td class="l"><b>{e(code)}</b> {e(name)}</td>'


def _share(n: int, total: int) -> str:
    if not n:
        return '<td class="z">·</td>'
    pct = 100.0 * n / total if total else 0.0
    return f'<td title="{n} of {total} recordings">{n} <small>({pct:.0f} %)</small></td>'


def crosstab_html(table: Crosstab, heading: str) -> str:
    if not table.columns:
        return '<p class="none">No recordings.</p>'
    head = "".join(f"<th>{e(c)}</th>" for c in table.columns)
    totals = "".join(f"<td>{table.totals.get(c, 0)}</td>" for c in table.columns)
    rows = [f'<tr><th class="l">{e(heading)}</th>{head}</tr>']
    rows.append(f'<tr><td class="l"><i>recordings</i></td>{totals}</tr>')
    for code in table.codes:
        cells = "".join(
            _share(table.hits.get((code, c), 0), table.totals.get(c, 0)) for c in table.columns
        )
        rows.append(f"<tr>{_rule_cell(code)}{cells}</tr>")
    if not table.codes:
        rows.append(f'<tr><td class="l" colspan="{len(table.columns) + 1}">no findings</td></tr>')
    return f'<table class="grid">{"".join(rows)}</table>'


@dataclass(frozen=True, slots=True)
class Worst:
    key: str
    path: str
    sha256: str | None
    format: str
    release: str
    vehicle: str
    start: str
    status: str
    errors: int
    warnings: int
    info: int


def worst(fleet: Fleet, n: int) -> list[Worst]:
    """The ``n`` recordings with the most errors (then warnings), or that could not be linted."""
    rows = fleet.recordings.to_pylist()
    rows.sort(key=lambda r: (-(r["errors"] or 0), -(r["warnings"] or 0), str(r["path"])))
    out = []
    for r in rows[:n]:
        if not (r["errors"] or r["warnings"]):
            break
        start = r["start_time"]
        out.append(
            Worst(
                key=str(r["key"]),
                path=str(r["path"]),
                sha256=r["sha256"],
                format=str(r["format"]),
                release=str(r["px4_release"] or f"unknown (judged as {r['px4']})"),
                vehicle=str(r["vehicle"]),
                start="" if start is None else start.strftime("%Y-%m-%d %H:%M UTC"),
                status=str(r["status"]),
                errors=int(r["errors"] or 0),
                warnings=int(r["warnings"] or 0),
                info=int(r["info"] or 0),
            )
        )
    return out


def report_name(row: Worst) -> str:
    """The file name of a recording's own report beside the page (``reports/NAME``)."""
    ident = row.sha256 or hashlib.sha256(row.path.encode("utf-8", "surrogatepass")).hexdigest()
    ident = ident[:16]
    return f"{ident}.html"


def worst_html(rows: list[Worst], links: dict[str, str]) -> str:
    if not rows:
        return '<p class="none">No recording has an error or a warning.</p>'
    head = (
        '<tr><th class="l">recording</th><th>errors</th><th>warnings</th><th>info</th>'
        '<th class="l">format</th><th class="l">PX4 release</th><th class="l">vehicle</th>'
        '<th class="l">start</th><th class="l">lint</th><th class="l">report</th></tr>'
    )
    body = []
    for r in rows:
        link = links.get(r.key)
        cell = f'<a href="{e(link)}">report</a>' if link else '<span class="none">none</span>'
        body.append(
            f'<tr><td class="path">{e(r.path)}</td><td class="error">{r.errors}</td>'
            f'<td class="warning">{r.warnings}</td><td>{r.info}</td><td class="l">{e(r.format)}'
            f'</td><td class="l">{e(r.release)}</td><td class="l">{e(r.vehicle)}</td>'
            f'<td class="l">{e(r.start)}</td><td class="l">{e(r.status)}</td>'
            f'<td class="l">{cell}</td></tr>'
        )
    return f'<table class="grid">{head}{"".join(body)}</table>'


def changes_html(fleet: Fleet) -> str:
    """The newest run beside the one before: the share of its recordings each rule fired on."""
    if not fleet.runs:
        return '<p class="none">No run yet.</p>'
    last = fleet.runs[-1]
    if len(fleet.runs) == 1:
        return f'<p class="note">One run so far ({e(_run_label(last))}): nothing to compare.</p>'
    before = fleet.runs[-2]
    table = crosstab(fleet, "run_id", keep=[before, last])
    rows = [
        f'<tr><th class="l">rule</th><th>{e(_run_label(before))}</th>'
        f"<th>{e(_run_label(last))}</th><th>change</th></tr>",
        f'<tr><td class="l"><i>recordings linted</i></td><td>{table.totals.get(before, 0)}</td>'
        f"<td>{table.totals.get(last, 0)}</td><td></td></tr>",
    ]
    for code in table.codes:
        old, new = (table.hits.get((code, r), 0) for r in (before, last))
        n_old, n_new = (table.totals.get(r, 0) for r in (before, last))
        delta = 100.0 * (new / n_new if n_new else 0.0) - 100.0 * (old / n_old if n_old else 0.0)
        if not old:
            change, css = "new", "up"
        elif not new:
            change, css = "gone", "down"
        else:
            change = f"{delta:+.0f} points"
            css = "up" if delta >= 1 else ("down" if delta <= -1 else "")
        rows.append(
            f"<tr>{_rule_cell(code)}{_share(old, n_old)}"
            f'{_share(new, n_new)}<td class="{css}">{change}</td></tr>'
        )
    note = (
        '<p class="note">Each run lints only recordings it had not seen (unless forced): the '
        "shares compare the flights of two nights.</p>"
    )
    return note + f'<table class="grid">{"".join(rows)}</table>'


def _run_label(run_id: str) -> str:
    """``20261124T021500123456Z`` as ``2026-11-24 02:15 UTC``."""
    if len(run_id) >= 13 and run_id[8] == "T":
        return f"{run_id[:4]}-{run_id[4:6]}-{run_id[6:8]} {run_id[9:11]}:{run_id[11:13]} UTC"
    return run_id


def summary_html(fleet: Fleet) -> str:
    r = fleet.recordings
    total = r.num_rows
    if not total:
        return '<p class="none">The dataset holds no recording yet.</p>'
    with_errors = pc.sum(pc.greater(r.column("errors"), 0)).as_py() or 0
    unfinished = pc.sum(pc.not_equal(r.column("status"), "linted")).as_py() or 0
    incomplete = pc.sum(pc.invert(r.column("complete"))).as_py() or 0
    hours = (pc.sum(r.column("duration_s")).as_py() or 0.0) / 3600
    return (
        f'<p class="verdict">{total} recordings ({hours:.1f} flight hours) in '
        f"{len(fleet.runs)} runs; {with_errors} with errors ({100.0 * with_errors / total:.0f} %), "
        f"{incomplete} not read completely, {unfinished} whose lint did not finish.</p>"
    )


def render(fleet: Fleet, links: dict[str, str], worst_rows: list[Worst]) -> str:
    weeks = sorted(set(fleet.recordings.column("week").to_pylist()))[-WEEKS:]
    sections = [
        ("changes", "What changed since the last run", changes_html(fleet)),
        (
            "weeks",
            "Findings per rule per week",
            '<p class="note">Recordings the rule fired on, of the week\'s recordings (the week '
            "the flight started, else the week it was linted).</p>"
            + crosstab_html(crosstab(fleet, "week", keep=weeks), "rule / ISO week"),
        ),
        (
            "releases",
            "Per PX4 release",
            '<p class="note">The release each recording names; <i>unknown</i> where it names '
            "none (it was judged with the profile set or assumed).</p>"
            + crosstab_html(crosstab(fleet, "px4_release"), "rule / release"),
        ),
        (
            "vehicles",
            "Per vehicle type",
            crosstab_html(crosstab(fleet, "vehicle"), "rule / vehicle"),
        ),
        ("worst", "The worst recordings", worst_html(worst_rows, links)),
    ]
    nav = " · ".join(f'<a href="#{ident}">{e(title)}</a>' for ident, title, _ in sections)
    body = "".join(f'<section id="{i}"><h2>{e(t)}</h2>{html}</section>' for i, t, html in sections)
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>fuzzoff fleet</title><style>{CSS}{EXTRA_CSS}</style></head><body>"
        f"<header><h1>fuzzoff fleet</h1><p>fuzzoff {e(__version__)}</p></header>"
        f"<main>{summary_html(fleet)}<p>{nav}</p>{body}</main></body></html>\n"
    )
