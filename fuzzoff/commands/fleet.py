"""``fuzzoff fleet DIR``: the fleet page over a dataset ``lint --format parquet`` wrote.

The page goes to ``--output`` (default ``DIR/fleet.html``); the worst recordings' own HTML
reports go beside it in ``reports/``, made by linting those recordings again (from their path
or URL, with this folder's configuration and the options given here), so that each link opens
the report ``fuzzoff lint --format html`` gives for it. ``--no-reports`` leaves them out.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from fuzzoff.commands import add_command
from fuzzoff.commands._common import add_profile_options, settings_from_args, write_output
from fuzzoff.config import ConfigError, Settings
from fuzzoff.findings import Report
from fuzzoff.fleet import require


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "fleet")
    parser.add_argument("dataset", metavar="DIR", help="the folder of lint --format parquet")
    parser.add_argument("--output", "-o", metavar="FILE", help="the page (default DIR/fleet.html)")
    parser.add_argument(
        "--worst", type=int, default=20, metavar="N", help="recordings in the worst list (20)"
    )
    parser.add_argument(
        "--no-reports",
        action="store_true",
        help="do not lint the worst recordings again for their own reports",
    )
    add_profile_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    require("parquet", "fuzzoff fleet")
    from fuzzoff.fleet.dataset import DatasetError
    from fuzzoff.fleet.page import Fleet, render, report_name, worst

    root = Path(args.dataset)
    if not root.is_dir():
        raise ConfigError(f"no such dataset folder: {args.dataset}")
    if args.worst < 0:
        raise ConfigError("--worst must be 0 or more")
    settings = settings_from_args(args)
    try:
        fleet = Fleet.load(root)
    except DatasetError as exc:
        raise ConfigError(str(exc)) from None
    if fleet.recordings.num_rows == 0:
        raise ConfigError(f"{args.dataset}: no recordings (write them with lint --format parquet)")
    page = Path(args.output) if args.output and args.output != "-" else root / "fleet.html"
    rows = worst(fleet, args.worst)
    links: dict[str, str] = {}
    if not args.no_reports:
        for row in rows:
            name = report_name(row)
            _own_report(row.path, page.parent / "reports" / name, settings)
            links[row.key] = f"reports/{name}"
    write_output(render(fleet, links, rows), args.output or str(page))
    if args.output != "-":
        print(f"fleet page written to {page}", file=sys.stderr)
    return 0


def _own_report(target: str, where: Path, settings: Settings) -> None:
    """The recording's HTML report, as ``fuzzoff lint TARGET --format html`` writes it."""
    from fuzzoff.engine import lint_file_with_timelines
    from fuzzoff.fleet.task import lint_target
    from fuzzoff.report import renderer

    outcome = lint_target(target, settings, lint=lint_file_with_timelines)
    assert outcome.report is not None
    write_output(renderer("html")(Report([outcome.report]), settings), str(where))
