"""``fuzzoff fuzz --against sitl:RELEASE``: the options and the run (``fuzzoff.sitl.against``).

``--transport ros2`` sends the streams over PX4's ROS 2 bridge (a bundle built with it): the
campaign moves into a private network namespace first (root), then runs as over MAVLink.

Exit status: 0 PX4 and the gate model agreed on every stream judged, 1 a disagreement was
found (saved as a reproducer), 2 a usage error, no PX4 build, a PX4 that could not be run, a
budget that sent no stream, or a reproducer that could not be saved.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from fuzzoff.config import ConfigError
from fuzzoff.report.sanitize import printable

USAGE = "expected sitl:RELEASE (a bundled PX4 SITL, e.g. sitl:1.15), or sitl with --px4-build DIR"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    live = parser.add_argument_group("against a real PX4 (docs/fuzz.md)")
    live.add_argument(
        "--against",
        metavar="sitl:RELEASE",
        help="send generated streams (MAVLink, or ROS 2 over PX4's bridge with --transport ros2)"
        " to a PX4 SITL this campaign starts, and compare what PX4 does with the gate model"
        " (default budget 300 s)",
    )
    live.add_argument(
        "--px4-build", metavar="DIR", type=Path, help="with --against: your own PX4 SITL build"
    )
    live.add_argument(
        "--instance", type=int, default=0, help="with --against: PX4_INSTANCE (0-99; default 0)"
    )
    live.add_argument(
        "--shrink-runs",
        type=int,
        metavar="N",
        help="with --against: live runs to simplify each disagreement (default 4)",
    )


NOT_WITH_AGAINST = {
    "from_": "--from",
    "property": "--property",
    "px4": "--px4 (the release is the one of --against)",
    "param": "--param (the campaign draws the parameters and sets them on PX4)",
    "seeds": "--seeds (one PX4, one seed: --seed)",
    "scheduler": "--scheduler (the campaign runs one PX4 here)",
}


def check_not_live(args: argparse.Namespace) -> None:
    """The live options are refused without ``--against``."""
    for name, option in (("px4_build", "--px4-build"), ("shrink_runs", "--shrink-runs")):
        if getattr(args, name) is not None:
            raise ConfigError(f"{option} goes with --against sitl:RELEASE")


def _release(text: str, px4_build: Path | None) -> str | None:
    scheme, _, release = text.partition(":")
    if scheme != "sitl" or (not release and px4_build is None):
        raise ConfigError(f"--against {text!r}: {USAGE}")
    return release or None


def _checked(args: argparse.Namespace) -> str:
    """The options' own checks (no bundle needed); the SITL vehicle (``airframes.AIRFRAMES``)."""
    from fuzzoff.sitl import airframes
    from fuzzoff.sitl.bundle import MAX_INSTANCE

    for name, option in NOT_WITH_AGAINST.items():
        if getattr(args, name, None):
            raise ConfigError(f"{option} does not go with --against")
    if args.transport not in (None, "mavlink", "ros2"):
        raise ConfigError(
            f"--transport {args.transport}: --against sends MAVLink, or ROS 2 over PX4's bridge"
        )
    if args.format not in ("terminal", "json"):
        raise ConfigError(f"--format {args.format}: --against reports as terminal or json")
    if args.examples is not None and args.examples < 1:
        raise ConfigError("--examples must be at least 1")
    if args.budget is not None and not (math.isfinite(args.budget) and args.budget > 0):
        raise ConfigError(f"--budget {args.budget:g}: expected a finite number of seconds above 0")
    if not 0 <= args.instance <= MAX_INSTANCE:
        raise ConfigError(f"--instance {args.instance}: expected 0 to {MAX_INSTANCE}")
    if args.shrink_runs is not None and args.shrink_runs < 0:
        raise ConfigError(f"--shrink-runs {args.shrink_runs}: expected 0 or more")
    try:
        return airframes.airframe_named(args.vehicle or airframes.DEFAULT).vehicle
    except airframes.AirframeError as exc:
        raise ConfigError(str(exc)) from None


def run(args: argparse.Namespace) -> int:
    from fuzzoff.commands._common import check_save_dir, settings_from_args, write_output
    from fuzzoff.fuzz.reproducers import DEFAULT_DIR
    from fuzzoff.sitl import airframes, bundle
    from fuzzoff.sitl.against import (
        DEFAULT_BUDGET_S,
        SHRINK_RUNS,
        AgainstConfig,
        Transport,
        run_against,
    )
    from fuzzoff.sitl.against_report import to_json, to_terminal

    vehicle = _checked(args)
    release = _release(args.against, args.px4_build)
    transport: Transport = "ros2" if args.transport == "ros2" else "mavlink"
    try:
        build = bundle.find_build(release, args.px4_build)
        if transport == "ros2":
            _check_bridge(args.against, build)
        airframes.boot_env(build, vehicle)  # refused here when the build cannot fly it
    except airframes.AirframeError as exc:
        raise ConfigError(str(exc)) from None
    except bundle.BundleError as exc:
        reason = str(exc).removeprefix(f"--release {release}: ")
        raise ConfigError(f"--against {args.against}: {reason}") from None
    save_dir = None
    if not args.no_save:
        save_dir = Path(args.save_dir) if args.save_dir else DEFAULT_DIR
        check_save_dir(save_dir, f"--save-dir {save_dir}" if args.save_dir else None)
    budget = args.budget if args.budget is not None or args.examples else DEFAULT_BUDGET_S
    config = AgainstConfig(
        build=build,
        instance=args.instance,
        vehicle=vehicle,
        budget_s=budget,
        examples=args.examples,
        seed=args.seed,
        shrink_runs=SHRINK_RUNS if args.shrink_runs is None else args.shrink_runs,
        settings=settings_from_args(argparse.Namespace(ignore=args.ignore)),
        save_dir=save_dir,
        transport=transport,
    )

    def log(line: str) -> None:
        if not args.quiet:
            print(f"fuzzoff: {printable(line, 400)}", file=sys.stderr, flush=True)

    if transport == "ros2":
        _enter_namespace()
    try:
        result = run_against(config, log)
    except OSError as exc:  # a reproducer that could not be written
        where = f" ({exc.filename})" if exc.filename else ""
        print(f"error: {exc.strerror or exc}{where}", file=sys.stderr)
        return 2
    text = to_json(result) if args.format == "json" else to_terminal(result)
    write_output(text, args.output)
    return _status(result)


def _check_bridge(against: str, build: Any) -> None:
    """A ROS 2 campaign needs a build with the bridge, cyclonedds and a private network."""
    from fuzzoff.sitl import bundle
    from fuzzoff.sitl.ros2.run import missing

    if not bundle.has_bridge(build):
        root = build.folder.parent
        bridged = [r for r in bundle.releases(root) if bundle.has_bridge(bundle.Build(root / r, r))]
        have = f"; bundles with it: {', '.join(bridged)}" if bridged else ""
        raise ConfigError(
            f"--against {against} --transport ros2: PX4 {build.release} is built without the"
            f" ROS 2 bridge (uxrce_dds_client){have}"
        )
    why = missing()
    if why is not None:
        raise ConfigError(f"--against {against} --transport ros2: {why}")


def _enter_namespace() -> None:
    """This process moves into a private network namespace (DDS must stay on this machine)."""
    from fuzzoff.sitl.ros2 import netns

    try:
        netns.enter()
    except netns.NamespaceError as exc:
        raise ConfigError(f"--transport ros2: a private network namespace: {exc}") from None


def _status(result: Any) -> int:
    if result.stopped and not result.search:
        print(f"error: {printable(result.stopped)}", file=sys.stderr)
        return 2
    if result.disagreements:
        return 1
    if not any(e.status != "failed" for e in result.search):
        why = f": {printable(result.stopped)}" if result.stopped else ""
        print(f"error: no stream was judged{why}", file=sys.stderr)
        return 2
    if result.stopped:
        print(f"error: the campaign stopped early: {printable(result.stopped)}", file=sys.stderr)
        return 2
    return 0
