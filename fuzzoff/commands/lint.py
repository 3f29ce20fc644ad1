"""``fuzzoff lint PATH...``: check recordings against the rule catalog."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, Progress, TaskID, TextColumn, TimeRemainingColumn

from fuzzoff.commands._common import (
    add_output_options,
    add_profile_options,
    add_rule_options,
    settings_from_args,
    write_output,
)
from fuzzoff.config import ConfigError, Settings
from fuzzoff.engine import lint_file, lint_paths
from fuzzoff.findings import Report
from fuzzoff.report import renderer
from fuzzoff.report.sanitize import printable
from fuzzoff.report.terminal import print_report
from fuzzoff.report.timelines import lint_with_timelines
from fuzzoff.sources import find_recordings


def add_parser(sub: Any) -> None:
    parser = sub.add_parser("lint", help="lint recordings (tlog, ULog, MCAP, ROS 2 and ROS 1 bags)")
    parser.add_argument("paths", nargs="+", metavar="PATH", help="files, bag folders or folders")
    add_profile_options(parser)
    add_rule_options(parser)
    add_output_options(parser)
    parser.add_argument("--jobs", "-j", type=int, default=1, help="lint files in N processes")
    parser.add_argument(
        "--quiet", "-q", action="store_true", help="only findings at the fail level"
    )
    parser.add_argument("--statistics", action="store_true", help="counts per rule")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.set_defaults(run=run)


def _lint_with_progress(paths: list[str], settings: Settings, console: Console) -> Report:
    """One file at a time with a progress bar on the terminal (long files take seconds)."""
    report = Report()
    files = [f for p in paths for f in find_recordings(Path(p))]
    columns = (TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        for f in files:
            task = progress.add_task(printable(f.name, 60), total=1.0)

            def advance(fraction: float, task: TaskID = task) -> None:
                progress.update(task, completed=fraction)

            report.files.append(lint_file(f, settings, progress=advance))
            progress.remove_task(task)
    return report


def run(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    if args.jobs < 1:
        raise ConfigError("--jobs must be at least 1")
    missing = [p for p in args.paths if not Path(p).exists()]
    if missing:
        raise ConfigError(f"no such file or folder: {missing[0]}")
    console = Console(stderr=False, highlight=False)
    terminal = args.format == "terminal"
    show_progress = terminal and console.is_terminal and not args.no_progress and args.jobs == 1
    if show_progress:
        report = _lint_with_progress(args.paths, settings, console)
    elif args.format == "html":  # the HTML report plots each vehicle's timeline
        report = lint_with_timelines(args.paths, settings, jobs=args.jobs)
    else:
        report = lint_paths(args.paths, settings, jobs=args.jobs)
    if terminal:
        if args.output:
            with open(args.output, "w", encoding="utf-8") as fh:
                print_report(
                    Console(file=fh, no_color=True, width=160, force_terminal=False),
                    report,
                    settings.fail_on,
                    quiet=args.quiet,
                    statistics=args.statistics,
                )
        else:
            print_report(
                console, report, settings.fail_on, quiet=args.quiet, statistics=args.statistics
            )
    else:
        write_output(renderer(args.format)(report, settings), args.output)
    for f in report.files:
        for line in f.problems:
            print(f"fuzzoff: {printable(line)}", file=sys.stderr)
    return report.exit_status(settings.fail_on)
