"""``fuzzoff lint PATH...``: check recordings against the rule catalog."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from fuzzoff.commands import add_command
from fuzzoff.commands._common import (
    add_fleet_options,
    add_profile_options,
    add_report_options,
    add_rule_options,
    check_output,
    existing_paths,
    render_rich,
    report_targets,
    settings_from_args,
    settings_per_recording,
    write_output,
)
from fuzzoff.config import ConfigError, Settings
from fuzzoff.engine import lint_file, lint_paths, lint_with_timelines
from fuzzoff.findings import Report
from fuzzoff.fleet import fleet_wanted
from fuzzoff.formats import RECORDING_SUFFIXES, find_recordings, recordings_in
from fuzzoff.report import FORMATS, renderer
from fuzzoff.report.sanitize import printable


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "lint")
    parser.add_argument(
        "paths",
        nargs="*",
        metavar="PATH",
        help="files, bag folders or folders (default: the current folder)",
    )
    add_profile_options(parser)
    add_rule_options(parser)
    add_report_options(parser, (*FORMATS, "parquet"))
    parser.add_argument("--jobs", "-j", type=int, default=1, help="lint files in N processes")
    parser.add_argument(
        "--quiet", "-q", action="store_true", help="only findings at the fail level"
    )
    parser.add_argument("--statistics", action="store_true", help="counts per rule")
    parser.add_argument(
        "--verbose",
        "-v",
        action="store_true",
        help="each finding in full: what the docs require, what PX4 does, the exact place",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_fleet_options(parser)
    parser.set_defaults(run=run)


def _lint(
    args: argparse.Namespace, paths: list[str], settings: Settings, formats: set[str]
) -> Report:
    """One lint for every report asked for: with the timelines the HTML report plots, with a
    progress bar on stderr where a person watches it, whatever the reports' formats (a long
    file, or one that is garbage after a good start, can take a while; rich is imported only
    then: the machine-readable formats need not pay for it at start-up)."""
    if "html" in formats:
        return lint_with_timelines(paths, settings, jobs=args.jobs)
    if sys.stderr.isatty() and not args.no_progress and args.jobs == 1:
        return _lint_with_progress(paths, settings)
    return lint_paths(paths, settings, jobs=args.jobs)


def _lint_with_progress(paths: list[str], settings: Settings) -> Report:
    """One file at a time with a progress bar on stderr's terminal (long files take seconds)."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TaskID, TextColumn, TimeRemainingColumn

    report = Report()
    columns = (TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn())
    console = Console(stderr=True, highlight=False)
    with Progress(*columns, console=console, transient=True) as progress:
        for f in recordings_in(paths):
            task = progress.add_task(printable(f.name, 60), total=1.0)

            def advance(fraction: float, task: TaskID = task) -> None:
                progress.update(task, completed=fraction)

            report.files.append(lint_file(f, settings, progress=advance))
            progress.remove_task(task)
    return report


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


def run(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    if args.jobs < 1:
        raise ConfigError("--jobs must be at least 1")
    # As ruff: no path means the current folder.
    args.paths = args.paths or ["."]
    if fleet_wanted(args):
        from fuzzoff.fleet.lint_run import run_fleet

        return run_fleet(args, settings, _terminal)
    existing_paths(args.paths)
    # A folder with nothing to lint is a mistake (a wrong path, a recording step that failed):
    # passing it would turn a CI job green without looking at a single flight.
    # Each folder is searched once, here; the linting takes the recordings found.
    found = [(p, find_recordings(Path(p))) for p in args.paths]
    empty = [p for p, recordings in found if Path(p).is_dir() and not recordings]
    if empty:
        suffixes = ", ".join(RECORDING_SUFFIXES)
        raise ConfigError(f"no recordings in {empty[0]} (searched for {suffixes} and bag folders)")
    paths = [str(f) for _, recordings in found for f in recordings]
    targets = report_targets(args.format, args.output)
    for _, output in targets:
        check_output(output, paths)
    settings_per_recording(settings, paths)
    report = _lint(args, paths, settings, {fmt for fmt, _ in targets})
    for fmt, output in targets:
        if fmt == "terminal":
            _terminal(args, report, settings, output)
        else:
            write_output(renderer(fmt)(report, settings), output)
    malformed = settings.enabled("OFB004")  # read around, nothing lost: the user may silence it
    for f in report.files:
        for line in [*f.problems, *(f.malformed if malformed else [])]:
            print(f"fuzzoff: {printable(line)}", file=sys.stderr)
    return report.exit_status(settings.fail_on)
