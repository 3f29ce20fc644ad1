"""``fuzzoff gate PATH``: the gate model's timeline beside the recorded mode.

Each row is a model transition (time, what, message, the docs/gate.md section that explains it,
``U`` for behaviour not verified on PX4) or a recorded mode change (``recorded``). A loss whose
time is PX4's 10 Hz check window is dated at the window's end, ``earliest_s`` its start;
``seen_in`` names where the recording shows PX4's own timing when the model took it from
there. Rows where the recording and the model differ beyond the profile's evaluation slack are
``disagreement`` rows naming both.
Exit status: 0 the model and the recording agree (or the recording has no mode), 1 they
disagree somewhere, 2 usage error or the recording could not be read completely.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from fuzzoff import __version__
from fuzzoff.commands import add_command
from fuzzoff.commands._common import (
    add_config_option,
    add_profile_options,
    check_output,
    existing_paths,
    settings_from_args,
    write_output,
)
from fuzzoff.findings import FileReport
from fuzzoff.gate_timeline import Row, gate_report
from fuzzoff.report.sanitize import escape_bidi, printable

SEE = 21
"""Width of the ``see`` column: the longest section, ``gate.md#before-switch``."""


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "gate")
    parser.epilog = (
        "exit status: 0 the model and the recorded mode history agree (or the recording has no "
        "mode), 1 they differ somewhere, 2 a usage error or a recording that could not be read "
        "completely"
    )
    parser.add_argument("path", metavar="PATH", help="a recording (any supported format)")
    add_profile_options(parser)
    add_config_option(parser)
    parser.add_argument("--format", choices=("terminal", "json"), default="terminal")
    parser.add_argument("--output", "-o", metavar="FILE", help="write the timeline here")
    parser.add_argument(
        "--no-controllers", action="store_true", help="leave out the 'controller' rows"
    )
    parser.set_defaults(run=run)


def _terminal(report: FileReport, rows: dict[str, list[Row]]) -> str:
    lines = [f"{printable(report.path)}: {report.format}, {report.profile.describe()}"]
    for vehicle, vrows in rows.items():
        has_recorded = any(r["source"] == "recorded" for r in vrows)
        lines.append("")
        lines.append(
            f"vehicle {printable(vehicle) or '(default)'}"
            + ("" if has_recorded else " (the recording has no mode: model only)")
        )
        lines.append(f"{'time s':>9}  {'model':<18} {'see':<{SEE}} {'':1} {'recorded':<14} message")
        for r in vrows:
            mark = "U" if r["unverified"] else ""
            if r["source"] == "recorded":
                line = f"{r['time_s']:9.3f}  {'':<18} {'':<{SEE}} {'':1} {r['message']:<14}"
            else:
                see = (r["see"] or "").removeprefix("docs/")
                what = r["what"].upper() if r["what"] == "disagreement" else r["what"]
                line = f"{r['time_s']:9.3f}  {what:<18} {see:<{SEE}} {mark:1} {'':<14} "
                line += printable(r["message"], 200)
            lines.append(line.rstrip())
        differ = [r for r in vrows if r["what"] == "disagreement"]
        if differ:
            lines.append(f"  {len(differ)} place(s) where the recording and the model differ:")
            lines += [f"    {r['time_s']:.2f} s  {printable(r['message'], 200)}" for r in differ]
        elif has_recorded:
            lines.append("  the recorded mode history agrees with the model")
    if any(r["unverified"] for vrows in rows.values() for r in vrows):
        lines.append("")
        lines.append("U = behaviour not verified on PX4 yet (docs/gate.md#unverified)")
    for problem in report.problems:
        lines.append(f"incomplete: {printable(problem)}")
    return "\n".join(lines) + "\n"


def _json(report: FileReport, rows: dict[str, list[Row]]) -> str:
    data = {
        "tool": "fuzzoff",
        "version": __version__,
        "files": [
            {
                "path": report.path,
                "format": report.format,
                "profile": report.to_json()["profile"],
                "complete": report.complete,
                "problems": list(report.problems),
                "vehicles": [
                    {
                        "vehicle": vehicle,
                        "timeline": vrows,
                        "disagreements": [r for r in vrows if r["what"] == "disagreement"],
                    }
                    for vehicle, vrows in rows.items()
                ],
            }
        ],
    }
    return escape_bidi(json.dumps(data, indent=2, ensure_ascii=False)) + "\n"


def run(args: argparse.Namespace) -> int:
    existing_paths([args.path])
    check_output(args.output, [args.path])
    settings = settings_from_args(args)
    report, rows = gate_report(args.path, settings, controllers=not args.no_controllers)
    text = _json(report, rows) if args.format == "json" else _terminal(report, rows)
    write_output(text, args.output)
    for line in [*report.problems, *report.malformed]:
        print(f"fuzzoff: {printable(line)}", file=sys.stderr)
    if not report.complete:
        return 2
    disagree = any(r["what"] == "disagreement" for vrows in rows.values() for r in vrows)
    return 1 if disagree else 0
