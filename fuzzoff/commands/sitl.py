"""``fuzzoff sitl``: run a scenario or replay a recording on a real PX4 SITL, with a verdict.

``fuzzoff sitl run SCENARIO --release R`` and ``fuzzoff sitl replay FILE --release R`` start
a bundle from ``../shared/px4-sitl/`` (``$FUZZOFF_PX4_SITL``), or the user's PX4 build with
``--px4-build DIR``, in a private temporary folder, wait until PX4 is ready to arm, fly or
replay, stop PX4 and keep its ULog (cut to the topics fuzzoff reads) and the tlog of both
directions in ``--save-dir``. The verdict puts what PX4 did beside the gate model's prediction
for that release: exit 0 when they agree, 1 when they differ, 2 when the run could not be done.
``fuzzoff sitl list`` shows the scenarios and the bundles found.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import Any

from fuzzoff.commands import add_command
from fuzzoff.commands._common import parse_params, write_output
from fuzzoff.config import ConfigError
from fuzzoff.report.sanitize import printable


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "sitl")
    actions = parser.add_subparsers(dest="action", metavar="ACTION")
    actions.required = True
    run = actions.add_parser("run", help="fly a scenario program on a PX4 SITL")
    run.add_argument("scenario", metavar="SCENARIO", help="a name from 'fuzzoff sitl list'")
    run.add_argument(
        "--vehicle",
        metavar="V",
        help="the SIH airframe to fly the scenario on (quad, hex, fw, tailsitter, vtol,"
        " rover-ackermann; default: the scenario's own)",
    )
    replay = actions.add_parser("replay", help="replay a tlog (or its reproducer) on a PX4 SITL")
    replay.add_argument(
        "path", metavar="FILE", help="a .tlog, a reproducer's .expected.json; a bag with ros2"
    )
    replay.add_argument("--speed", type=float, default=1.0, help="time scale (0.01 to 100)")
    for p in (run, replay):
        p.add_argument(
            "--transport",
            choices=("mavlink", "ros2"),
            default="mavlink",
            help="ros2: a ROS 2 program or bag over PX4's bridge (uXRCE-DDS; cyclonedds, root)",
        )
        p.add_argument("--release", metavar="R", help="bundled PX4 release (1.16.2, 1.15)")
        p.add_argument("--px4-build", metavar="DIR", type=Path, help="your own SITL build")
        p.add_argument("--instance", type=int, default=0, help="PX4_INSTANCE (0-99; default 0)")
        p.add_argument(
            "--param",
            action="append",
            default=[],
            metavar="NAME=VALUE",
            help="PX4 parameter set with PARAM_SET and read back before the run (repeatable)",
        )
        p.add_argument(
            "--speed-factor",
            type=float,
            metavar="X",
            help="PX4_SIM_SPEED_FACTOR for SIH (faster than real time; see docs/sitl.md)",
        )
        p.add_argument("--save-dir", metavar="DIR", type=Path, help="keep the tlog and ULog here")
        p.add_argument("--format", choices=("terminal", "json"), default="terminal")
        p.add_argument("--output", "-o", metavar="FILE")
    actions.add_parser("list", help="the scenarios and the bundled PX4 releases")
    parser.set_defaults(run=run_command)


def _list() -> int:
    from fuzzoff.sitl.bundle import default_root, releases
    from fuzzoff.sitl.scenarios import SCENARIOS

    lines = ["scenarios:"]
    for s in SCENARIOS.values():
        kind = "clean" if s.kind == "clean" else f"hazard ({s.hazard})"
        lines.append(f"  {s.name:<26} {s.summary}; {kind}")
    from fuzzoff.sitl.airframes import AIRFRAMES

    lines.append("vehicles (--vehicle):")
    for a in AIRFRAMES.values():
        lines.append(f"  {a.vehicle:<26} PX4_SIM_MODEL={a.model}, judged as {a.fuzzoff_vehicle}")
    from fuzzoff.sitl.ros2.programs import PROGRAMS

    lines.append("ROS 2 programs (--transport ros2):")
    for p in PROGRAMS.values():
        kind = "clean" if p.kind == "clean" else f"hazard ({p.hazard})"
        lines.append(f"  {p.name:<26} {p.summary}; {kind}")
    found = releases()
    lines.append(f"PX4 SITL bundles in {default_root()}: {', '.join(found) or 'none'}")
    write_output("\n".join(lines) + "\n", None)
    return 0


def run_command(args: argparse.Namespace) -> int:
    if args.action == "list":
        return _list()
    if args.transport == "ros2":
        return _run_ros2(args)
    from fuzzoff.recording import SourceError
    from fuzzoff.sitl import bundle, run
    from fuzzoff.sitl.link import LinkError
    from fuzzoff.sitl.scenarios import SCENARIOS

    params = parse_params(args.param)
    env = {}
    if args.speed_factor is not None:
        if not 0.1 <= args.speed_factor <= 20:
            raise ConfigError(f"--speed-factor {args.speed_factor:g}: expected 0.1 to 20")
        env["PX4_SIM_SPEED_FACTOR"] = f"{args.speed_factor:g}"
    if args.action == "run" and args.scenario not in SCENARIOS:
        raise ConfigError(
            f"no scenario {args.scenario!r}; have {', '.join(SCENARIOS)} ('fuzzoff sitl list')"
        )
    if args.action == "replay" and not 0.01 <= args.speed <= 100:
        raise ConfigError(f"--speed {args.speed:g}: expected 0.01 to 100")
    try:
        build = bundle.find_build(args.release, args.px4_build)
    except bundle.BundleError as exc:
        raise ConfigError(str(exc)) from None
    save_dir = args.save_dir or Path(tempfile.mkdtemp(prefix="fuzzoff-sitl-"))

    def log(line: str) -> None:
        print(f"fuzzoff: {printable(line)}", file=sys.stderr)

    try:
        if args.action == "run":
            outcome = run.run_scenario(
                args.scenario, build, args.instance, save_dir, params, env, log, args.vehicle
            )
        else:
            recording, params, manual = _recording(Path(args.path), params)
            outcome = run.replay_on_bundle(
                recording, build, args.instance, save_dir, params, args.speed, env, log, manual
            )
    except (LinkError, bundle.BundleError, SourceError) as exc:
        print(f"error: {printable(str(exc))}", file=sys.stderr)
        return 2
    return report(outcome, args.format, args.output)


def _run_ros2(args: argparse.Namespace) -> int:
    """A ROS 2 program flown, or a bag replayed, over PX4's bridge: its recordings and what
    PX4 answered."""
    from fuzzoff.sitl import bundle
    from fuzzoff.sitl.ros2 import run as ros2_run
    from fuzzoff.sitl.ros2.programs import PROGRAMS

    if args.action == "run" and args.scenario not in PROGRAMS:
        raise ConfigError(
            f"no ROS 2 program {args.scenario!r}; have {', '.join(PROGRAMS)} ('fuzzoff sitl list')"
        )
    if args.speed_factor is not None or args.instance:
        raise ConfigError("--speed-factor and --instance are MAVLink-only for now")
    if args.param and args.action == "run":
        raise ConfigError("--param goes with a ROS 2 replay (set at PX4's boot), not a program")
    if getattr(args, "speed", 1.0) != 1.0:
        raise ConfigError("--speed is MAVLink-only for now: a ROS 2 replay keeps the bag's times")
    params: dict[str, float] = {}
    manual = False
    path = Path(args.path) if args.action == "replay" else Path()
    if args.action == "replay":
        path, params, manual = _ros2_recording(Path(args.path))
        params = {**params, **parse_params(args.param)}
    if getattr(args, "vehicle", None):
        from fuzzoff.sitl.airframes import AirframeError, airframe_for

        try:
            airframe_for(args.vehicle)
        except AirframeError as exc:
            raise ConfigError(str(exc)) from None
    try:
        build = bundle.find_bridge_build(args.release, args.px4_build)
    except bundle.BundleError as exc:
        raise ConfigError(str(exc)) from None
    save_dir = args.save_dir or Path(tempfile.mkdtemp(prefix="fuzzoff-sitl-"))

    def log(line: str) -> None:
        print(f"fuzzoff: {printable(line)}", file=sys.stderr)

    try:
        if args.action == "run":
            outcome = ros2_run.fly(args.scenario, build, save_dir, log, args.vehicle)
        else:
            if manual:
                log(
                    "the reproducer assumed a manual control (RC or joystick); a ROS 2 replay"
                    " sends none, so PX4's loss failsafe may differ from the campaign's"
                )
            outcome = ros2_run.replay_bag(path, build, save_dir, log, params)
    except ros2_run.FlightError as exc:
        print(f"error: {printable(str(exc))}", file=sys.stderr)
        return 2
    if args.format == "json":
        data = {
            **outcome.summary,
            "recordings": [str(p) for p in outcome.recordings],
        }
        write_output(json.dumps(data, indent=2) + "\n", args.output)
    else:
        write_output(ros2_run.render(outcome), args.output)
    return 0


def _ros2_recording(path: Path) -> tuple[Path, dict[str, float], bool]:
    """What a ROS 2 replay sends: a bag folder, an MCAP file, or a ROS 2 reproducer's
    recording with its setup (PX4 parameters, set at boot; whether it assumed manual
    control)."""
    reproducer_file = path.name.endswith(".expected.json")
    if not reproducer_file and not path.is_dir() and path.suffix.lower() != ".mcap":
        raise ConfigError(
            f"{path}: a ROS 2 replay takes a bag folder (metadata.yaml), an .mcap file or a"
            " ROS 2 reproducer's .expected.json"
        )
    if not path.exists():
        raise ConfigError(f"no such file: {path}")
    if reproducer_file:
        from fuzzoff.fuzz.reproducers import ReproducerError, load

        try:
            reproducer = load(path)
        except ReproducerError as exc:
            raise ConfigError(str(exc)) from None
        if reproducer.scenario is not None and reproducer.scenario.transport != "ros2":
            raise ConfigError(
                f"{path}: a {reproducer.scenario.transport} reproducer: replay it without"
                " --transport ros2"
            )
        setup = reproducer.setup
        params = dict(setup.params) if setup else {}
        return reproducer.recording, params, setup is not None and setup.manual_control
    return path, {}, False


def _recording(path: Path, params: dict[str, float]) -> tuple[Path, dict[str, float], bool]:
    """A tlog, or a reproducer's recording with its setup: its PX4 parameters (the command
    line's win) and whether it assumed manual control (then a MAVLink joystick is sent)."""
    if not path.exists():
        raise ConfigError(f"no such file: {path}")
    manual = False
    if path.name.endswith(".expected.json"):
        from fuzzoff.fuzz.reproducers import ReproducerError, load

        try:
            reproducer = load(path)
        except ReproducerError as exc:
            raise ConfigError(str(exc)) from None
        setup = reproducer.setup
        path, params = reproducer.recording, {**(setup.params if setup else {}), **params}
        manual = setup is not None and setup.manual_control
    if path.suffix.lower() != ".tlog":
        raise ConfigError(f"{path}: a replay sends MAVLink: only a .tlog recording")
    return path, params, manual


def report(outcome: Any, fmt: str, output: str | None) -> int:
    from fuzzoff.sitl.verdict import render

    verdict = outcome.verdict
    if fmt == "json":
        data = {
            "release": outcome.release,
            "tlog": str(outcome.tlog),
            "ulog": None if outcome.ulog is None else str(outcome.ulog),
            "steps": [
                {"px4_time_s": round(s.px4_t, 3), "what": s.what, "result": s.result}
                for s in outcome.steps
            ],
            "notes": outcome.notes,
            "verdict": None if verdict is None else verdict.to_json(),
        }
        text = json.dumps(data, indent=2) + "\n"
    else:
        lines = [f"PX4 {outcome.release}: tlog {outcome.tlog}"]
        if outcome.ulog is not None:
            lines.append(f"  ULog {outcome.ulog}")
        for s in outcome.steps:
            result = "" if s.result is None else f" (ack {s.result})"
            lines.append(f"  {s.px4_t:8.3f} s  {s.what}{result}")
        lines += [f"  {printable(n)}" for n in outcome.notes]
        text = "\n".join(lines) + "\n" + (render(verdict) if verdict else "no verdict\n")
    write_output(text, output)
    if verdict is None or (verdict.problems and not verdict.items):
        return 2
    return 0 if verdict.agree else 1
