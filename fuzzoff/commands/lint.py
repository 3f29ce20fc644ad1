"""``fuzzoff lint PATH...``: check recordings against the rule catalog."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from fuzzoff.commands import add_command
from fuzzoff.commands._common import (
    add_config_option,
    add_fleet_options,
    add_profile_options,
    add_report_options,
    add_rule_options,
    check_output,
    recordings_named,
    report_targets,
    resolve_recordings,
    settings_from_args,
)
from fuzzoff.commands._lint_output import (
    add_adoption_options,
    check_baseline,
    print_problems,
    settle,
    show_settings,
    write_report,
)
from fuzzoff.config import ConfigError, Settings
from fuzzoff.engine import Lint, Watch, lint_each, lint_file, lint_file_with_timelines
from fuzzoff.fleet import is_url
from fuzzoff.report import FORMATS
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
    add_config_option(parser)
    add_adoption_options(parser)
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
    parser.add_argument(
        "--with",
        dest="with_ulog",
        metavar="ULOG",
        help="PX4's ULog of the same flight: what the ROS 2 bag's companion sent and PX4 never"
        " received, and what PX4 did that the companion never saw (OFB108)",
    )
    add_fleet_options(parser)
    parser.set_defaults(run=run)


@contextmanager
def _watching(args: argparse.Namespace) -> Iterator[Watch | None]:
    """A progress bar on stderr where a person watches it, whatever the reports' formats (a
    long file, or one that is garbage after a good start, can take a while): a task per
    recording while it is linted, in this process only. rich is imported only then: the
    machine-readable formats need not pay for it at start-up."""
    if not sys.stderr.isatty() or args.no_progress or args.jobs != 1:
        yield None
        return
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    columns = (TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn())
    console = Console(stderr=True, highlight=False)
    with Progress(*columns, console=console, transient=True) as bar:

        @contextmanager
        def watch(path: str) -> Iterator[Callable[[float], None]]:
            task = bar.add_task(printable(Path(path).name, 60), total=1.0)
            try:
                yield lambda fraction: bar.update(task, completed=fraction)
            finally:
                bar.remove_task(task)

        yield watch


def run(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    if args.show_settings is not None:
        return show_settings(args.show_settings, settings)
    if args.jobs < 1:
        raise ConfigError("--jobs must be at least 1")
    # As ruff: no path means the current folder.
    args.paths = args.paths or ["."]
    if _fleet_wanted(args):
        if args.with_ulog is not None:
            raise ConfigError("--with compares one bag linted here: not with the fleet options")
        from fuzzoff.commands._lint_fleet import run_fleet

        return run_fleet(args, settings)
    paths = recordings_named(args.paths)
    targets = report_targets(args.format, args.output)
    for output in [*(out for _, out in targets), args.write_baseline]:
        check_output(output, paths)
    baseline = check_baseline(args)
    plan = resolve_recordings(settings, paths)
    # One lint for every report asked for, with the timelines the HTML report plots
    lint: Lint = lint_file_with_timelines if any(f == "html" for f, _ in targets) else lint_file
    with _watching(args) as watch:
        report = lint_each(plan, lint=lint, jobs=args.jobs, watch=watch)
    if args.with_ulog is not None:
        from fuzzoff.commands._with import add_delivery

        add_delivery(report, Path(args.with_ulog))
    resolved = dict(plan)

    def settings_for(path: str) -> Settings:
        return resolved.get(path) or settings.resolved_for(path)

    settings = settle(args, report, settings, settings_for, baseline)
    for fmt, output in targets:
        write_report(args, report, settings, fmt, output)
    print_problems(report, settings)  # OFB004's lines (nothing lost) unless it is silenced
    return settings.exit_status(report)


def _fleet_wanted(args: argparse.Namespace) -> bool:
    """Does this lint need the fleet path (a cluster, URLs, the dataset or its options)?"""
    return bool(
        args.scheduler is not None
        or "parquet" in (args.format or ())
        or args.timeout is not None
        or args.force
        or any(is_url(p) for p in args.paths)
    )
