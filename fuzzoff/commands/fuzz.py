"""``fuzzoff fuzz``: a seeded fuzz campaign against the gate model and the rules (docs/fuzz.md).

Exit status: 0 every property held, 1 a counterexample was found (saved as a reproducer under
``--save-dir``, by default ``.fuzzoff/reproducers/`` in the working folder), 2 usage error, an
unreadable ``--from`` recording, or a reproducer that could not be saved (the report still gives
its counterexample). fuzzoff's own known problems (``fuzz.known``) are left out and counted,
unless ``--include-known`` (for fuzzoff's developers).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from fuzzoff.commands import _against, add_command
from fuzzoff.commands._common import (
    add_scheduler_option,
    check_save_dir,
    parse_params,
    settings_from_args,
    write_output,
)
from fuzzoff.config import ConfigError, user_px4_profile
from fuzzoff.formats import SourceError, is_bag_folder
from fuzzoff.fuzz.campaign import CampaignConfig, CampaignResult, PropertyResult, run_campaign
from fuzzoff.fuzz.known import KNOWN
from fuzzoff.fuzz.properties import PROPERTIES
from fuzzoff.fuzz.reproducers import DEFAULT_DIR, save
from fuzzoff.fuzz.scenario import TRANSPORTS
from fuzzoff.profiles import ProfileError, vehicle_type_for
from fuzzoff.report import CampaignReport, campaign_renderer
from fuzzoff.report.sanitize import printable


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "fuzz")
    parser.epilog = (
        "exit status: 0 every property held, 1 a counterexample was found (saved under "
        f"--save-dir, default {DEFAULT_DIR}/), 2 a usage error, a --from recording that could "
        "not be read completely, a budget that ran no example, or a reproducer not saved"
    )
    parser.add_argument("--px4", metavar="VERSION", help="PX4 release or profile (default: all)")
    parser.add_argument("--vehicle", metavar="TYPE", help="vehicle type (default: all)")
    parser.add_argument("--transport", choices=TRANSPORTS, help="default: all")
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--budget", type=float, metavar="SECONDS", help="time budget")
    size.add_argument("--examples", type=int, metavar="N", help="examples per property")
    parser.add_argument("--seed", type=int, default=0, help="the campaign's seed (default 0)")
    parser.add_argument(
        "--property",
        action="append",
        choices=sorted(PROPERTIES),
        help="check only this property (repeatable; default all)",
    )
    parser.add_argument("--from", dest="from_", metavar="RECORDING", help="mutate this stream")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="PX4 parameter for --from (the campaign draws its own otherwise)",
    )
    parser.add_argument("--ignore", metavar="CODES", help="rules to switch off (fault planting)")
    parser.add_argument(
        "--include-known",
        action="store_true",
        help="for fuzzoff's developers: also fail on fuzzoff's own known problems "
        "(fuzzoff/fuzz/known.py), which are otherwise left out and counted",
    )
    # Leaving the known problems out was --known; it is the default now, still accepted.
    parser.add_argument("--known", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument(
        "--format", choices=("terminal", "json", "junit", "sarif"), default="terminal"
    )
    parser.add_argument("--output", "-o", metavar="FILE", help="write the report here")
    parser.add_argument(
        "--save-dir",
        metavar="DIR",
        help=f"where reproducers are saved (default {DEFAULT_DIR}/, made when one is)",
    )
    parser.add_argument("--no-save", action="store_true", help="do not save reproducers")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress display")
    add_scheduler_option(parser, "one campaign per seed")
    parser.add_argument(
        "--seeds",
        metavar="SEEDS",
        help="one campaign per seed (0-199, or 3,7,11), merged into one report; each seed "
        "runs what --seed N runs (docs/fleet.md)",
    )
    _against.add_arguments(parser)
    parser.set_defaults(run=run)


def _config(args: argparse.Namespace) -> CampaignConfig:
    try:
        px4, note = user_px4_profile(args.px4) if args.px4 else (None, None)
        vehicle = vehicle_type_for(args.vehicle) if args.vehicle else None
    except ProfileError as exc:
        raise ConfigError(f"--px4: {exc}" if "PX4" in str(exc) else str(exc)) from None
    if note:
        print(f"fuzzoff: --px4: {note}", file=sys.stderr)
    if args.examples is not None and args.examples < 1:
        raise ConfigError("--examples must be at least 1")
    if args.budget is not None and not (math.isfinite(args.budget) and args.budget > 0):
        raise ConfigError(f"--budget {args.budget:g}: expected a finite number of seconds above 0")
    ns = argparse.Namespace(ignore=args.ignore)
    settings = settings_from_args(ns)
    examples = args.examples if args.examples is not None else (None if args.budget else 100)
    config = CampaignConfig(
        px4=px4,
        vehicle=vehicle,
        transport=args.transport,
        examples=examples,
        budget_s=args.budget,
        seed=args.seed,
        properties=tuple(args.property or PROPERTIES),
        settings=settings,
        known=() if args.include_known else tuple(KNOWN),
    )
    if args.from_:
        from fuzzoff.fuzz.mutate import read_base, sent_keepalives

        config.properties = _from_properties(args.property)
        path = Path(args.from_)
        if path.is_dir() and not is_bag_folder(path):
            raise ConfigError(
                f"--from {args.from_}: a folder that is not a ROS 2 bag (no metadata.yaml); "
                "--from takes one recording"
            )
        try:
            config.base, config.base_problems = read_base(
                path, px4, vehicle, parse_params(args.param)
            )
        except SourceError as exc:
            raise ConfigError(exc.line()) from None
        except OSError as exc:
            raise ConfigError(f"{args.from_}: {exc.strerror or exc}") from None
        if not sent_keepalives(config.base):
            raise ConfigError(
                f"{args.from_}: no keep-alive as sent to the vehicle, so nothing to perturb: "
                "--from takes a recording of the companion's stream (a tlog, an MCAP, a ROS 2 "
                "or a ROS 1 bag with its setpoints; a ULog holds only the vehicle's copies)"
            )
    return config


def _from_properties(asked: list[str] | None) -> tuple[str, ...]:
    """The properties a ``--from`` campaign checks: not those that write the stream with
    fuzzoff's writers and read it back (``uses_files``). They test the writers and readers on
    the streams the campaign generates; a recording's events are a reader's output, with what
    no writer writes back as it was (the vehicle's identity from a HEARTBEAT, say), so they
    would report on fuzzoff's writers, not on the user's stream."""
    for name in asked or ():
        if PROPERTIES[name].uses_files:
            raise ConfigError(
                f"--property {name} tests fuzzoff's writers and readers on generated streams; "
                "it does not take --from"
            )
    return tuple(asked or (n for n, spec in PROPERTIES.items() if not spec.uses_files))


class _Progress:
    """A rich live line: property, examples, examples/s, failures (stderr, terminals only)."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled and sys.stderr.isatty()
        self.failures = 0
        self.progress: Any = None
        self.task: Any = None

    def __enter__(self) -> _Progress:
        if self.enabled:
            from rich.console import Console
            from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

            self.progress = Progress(
                SpinnerColumn(),
                TextColumn("{task.description}"),
                TextColumn("{task.completed} examples"),
                TextColumn("{task.fields[rate]}/s"),
                TextColumn("failures: {task.fields[failures]}"),
                TimeElapsedColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self.progress.__enter__()
            self.task = self.progress.add_task("fuzz", total=None, rate="-", failures=0)
        return self

    def __exit__(self, *exc: object) -> None:
        if self.progress is not None:
            self.progress.__exit__(None, None, None)

    def example(self, r: PropertyResult) -> None:
        if self.progress is None or r.examples % 5:
            return
        rate = f"{r.examples / r.seconds_so_far():.0f}" if r.seconds_so_far() else "-"
        self.progress.update(
            self.task,
            description=r.name,
            completed=r.examples,
            rate=rate,
            failures=self.failures + (1 if r.found_after else 0),
        )

    def done(self, r: PropertyResult) -> None:
        self.failures += 1 if r.failed else 0


def run(args: argparse.Namespace) -> int:
    if args.against is not None:  # a live campaign against a PX4 SITL
        return _against.run(args)
    _against.check_not_live(args)
    config = _config(args)
    label = f"--save-dir {args.save_dir}"
    if args.save_dir is None:
        args.save_dir = str(DEFAULT_DIR)
        label = f"{DEFAULT_DIR} (where reproducers go: --save-dir DIR or --no-save to change)"
    if not args.no_save:
        check_save_dir(Path(args.save_dir), label)
    unfinished: list[str] = []
    if args.scheduler is not None or args.seeds is not None:
        from fuzzoff.fleet.fuzz_run import run_seeds_of

        result, unfinished = run_seeds_of(args, config)
    else:
        with _Progress(not args.quiet) as progress:
            result = run_campaign(config, progress.example, progress.done)
    saved: dict[str, Path] = {}
    save_error = None
    if not args.no_save:
        saved, save_error = _save_all(result, Path(args.save_dir))
    margins = []
    if config.base is not None:
        from fuzzoff.fuzz.mutate import margins as find_margins

        margins = find_margins(config.base)
    report = CampaignReport(result, saved, margins)
    write_output(campaign_renderer(args.format)(report), args.output)
    if save_error is not None:
        print(f"error: {save_error}", file=sys.stderr)
        return 2
    for line in unfinished:
        print(f"error: {line}", file=sys.stderr)
    if unfinished:
        return 2
    if config.base_problems:
        # As lint: the campaign ran on the part that could be read; the status says the rest.
        for line in config.base_problems:
            print(f"fuzzoff: {printable(line)}", file=sys.stderr)
        return 2
    if result.unchecked:
        # Nothing was checked, so nothing held: not 0 (a CI job must not pass on it), and not
        # 1 either (no counterexample): the budget given was too small to run anything.
        budget = f"--budget {args.budget:g} s " if args.budget is not None else ""
        names = ", ".join(result.unchecked)
        print(f"error: {budget}ran no example of {names}: nothing was checked", file=sys.stderr)
        return 2
    return 1 if result.failed else 0


def _save_all(result: CampaignResult, directory: Path) -> tuple[dict[str, Path], str | None]:
    """The reproducers saved, by property, and why the rest could not be where ``directory``
    failed (the counterexamples are still in the report)."""
    saved = {}
    for r in result.results:
        if r.failed and r.counterexample is not None:
            try:
                saved[r.name] = save(
                    r.name,
                    r.counterexample,
                    r.problems,
                    directory,
                    cut_fraction=r.cut_fraction,
                    base=result.config.settings,
                    recorded_answers=result.config.base is not None,
                )
            except ValueError as exc:  # an event its transport's writer cannot carry
                print(f"fuzzoff: the {r.name} counterexample was not saved: {exc}", file=sys.stderr)
            except OSError as exc:
                reason = exc.strerror or str(exc)
                where = f" ({exc.filename})" if exc.filename else ""
                return saved, (
                    f"--save-dir {directory}: the {r.name} counterexample was not saved: "
                    f"{reason}{where}; it is in the report"
                )
    return saved, None
