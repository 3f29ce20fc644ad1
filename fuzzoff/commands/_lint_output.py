"""What ``fuzzoff lint`` writes once the recordings are linted, wherever they were (this
process, worker processes, a Dask cluster): each report asked for, and one stderr line per
damaged part of a recording."""

from __future__ import annotations

import argparse
import sys

from fuzzoff.commands._common import render_rich, write_output
from fuzzoff.config import Settings
from fuzzoff.findings import Report
from fuzzoff.report import renderer
from fuzzoff.report.sanitize import printable


def write_report(
    args: argparse.Namespace, report: Report, settings: Settings, fmt: str, output: str | None
) -> None:
    """One report in ``fmt`` to ``output`` (None: standard output)."""
    if fmt == "terminal":
        _terminal(args, report, settings, output)
    else:
        write_output(renderer(fmt)(report, settings), output)


def _terminal(
    args: argparse.Namespace, report: Report, settings: Settings, output: str | None
) -> None:
    from rich.console import Console

    from fuzzoff.report.terminal import print_report

    def draw(console: Console) -> None:
        print_report(
            console,
            report,
            settings.fail_on,
            quiet=args.quiet,
            statistics=args.statistics,
            verbose=args.verbose,
        )

    render_rich(draw, output)


def print_problems(report: Report, settings: Settings) -> None:
    """A line on stderr for each part of a recording not read (and read around, unless OFB004
    is silenced: nothing was lost)."""
    malformed = settings.enabled("OFB004")
    for f in report.files:
        for line in [*f.problems, *(f.malformed if malformed else [])]:
            print(f"fuzzoff: {printable(line)}", file=sys.stderr)
