"""``fuzzoff replay REPRODUCER``: re-check a saved reproducer, or stream it to a live PX4.

Without ``--to``: lint the recording with the reproducer's arguments and compare with its
expected findings (the corpus rule: same codes and severities, times within 0.05 s), then check
the property it broke again, on the stream it failed on (``fuzz.reproducers.recheck``): "still
fails" or "fixed". Exit 0 when the findings match and the property holds now (the bug is fixed),
1 when the findings differ or the property still fails, 2 when the reproducer cannot be used
(unreadable, or its recording missing, truncated or changed since it was saved).

With ``--to udp:HOST:PORT``: replay the recording's MAVLink stream (a tlog) into a running PX4
as a real client (``fuzzoff.sitl``): PX4 SITL listens on UDP 14580 (+ instance), so
``--to udp:127.0.0.1:14580``. The client waits for PX4 and its pre-arm checks, brings the vehicle
to the recording's starting state, sets the reproducer's parameters (read back, put back after),
sends on PX4's clock (``--speed`` to scale), records both directions (``--record``) and prints
what PX4 did beside the gate model's prediction: exit 0 when they agree, 1 when they differ,
2 when the replay could not be done.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from fuzzoff.commands import add_command
from fuzzoff.commands._common import write_output
from fuzzoff.config import ConfigError
from fuzzoff.fuzz.reproducers import ReproducerError, load, recheck, recording_problem
from fuzzoff.recording import SourceError
from fuzzoff.report.sanitize import printable

TIME_TOLERANCE_S = 0.05
MIN_SPEED, MAX_SPEED = 0.01, 100.0
"""``--speed`` range: a reproducer of a minute takes at most 100 minutes; above 100x the gaps
the gate reacts to (tens of milliseconds) are shorter than the sleep they are timed with."""


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "replay")
    parser.epilog = (
        "exit status (without --to): 0 the findings match and the property holds now (fixed), "
        "1 the findings differ or the property still fails, 2 the reproducer or its recording "
        "cannot be used (unreadable, missing, truncated or changed since it was saved)"
    )
    parser.add_argument("path", metavar="REPRODUCER", help="NAME.expected.json or its recording")
    parser.add_argument(
        "--to",
        metavar="udp:HOST:PORT",
        help="replay into a running PX4 there: udp:127.0.0.1:14580 for a SITL (PX4 listens on"
        " 14580 + instance; an IPv6 address in brackets: udp:[::1]:14580)",
    )
    parser.add_argument(
        "--record",
        metavar="FILE",
        help="with --to: the tlog of the exchange (default: a temp file)",
    )
    parser.add_argument(
        "--px4", metavar="VERSION", help="with --to: the release for the model if PX4 does not say"
    )
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="with --to: a PX4 parameter for the replay (PARAM_SET, read back, put back after)",
    )
    parser.add_argument(
        "--connect-timeout",
        type=float,
        default=10.0,
        metavar="S",
        help="with --to: seconds to wait for PX4's first HEARTBEAT",
    )
    parser.add_argument(
        "--ready-timeout",
        type=float,
        default=90.0,
        metavar="S",
        help="with --to: seconds to wait for PX4's pre-arm checks (1.15 needs about 40 s)",
    )
    parser.add_argument(
        "--speed",
        type=float,
        default=1.0,
        help=f"time scale for --to, from {MIN_SPEED:g} to {MAX_SPEED:g} (2 = twice as fast)",
    )
    parser.add_argument("--format", choices=("terminal", "json"), default="terminal")
    parser.add_argument("--output", "-o", metavar="FILE")
    parser.set_defaults(run=run)


def _key(f: dict[str, Any]) -> tuple[str, str, str]:
    return (str(f["code"]), str(f["severity"]), str(f.get("vehicle", "")))


def compare(expected: list[dict[str, Any]], actual: list[dict[str, Any]]) -> list[str]:
    """Missing and unexpected findings (also how tests/test_corpora.py matches the corpus)."""
    remaining = list(actual)
    problems = []
    for want in expected:
        hit = None
        for got in remaining:
            if _key(got)[:2] != _key(want)[:2]:
                continue
            if "vehicle" in want and want["vehicle"] != got.get("vehicle", ""):
                continue
            wt, gt = want.get("time_s"), got.get("time_s")
            if (wt is None) != (gt is None):
                continue
            if wt is None or gt is None or abs(float(wt) - float(gt)) <= TIME_TOLERANCE_S:
                hit = got
                break
        if hit is None:
            problems.append(f"missing {want['code']} {want['severity']} at {want.get('time_s')}")
        else:
            remaining.remove(hit)
    problems += [f"unexpected {f['code']} {f['severity']} at {f['time_s']}" for f in remaining]
    return problems


def run(args: argparse.Namespace) -> int:
    if not MIN_SPEED <= args.speed <= MAX_SPEED:  # NaN too
        raise ConfigError(f"--speed {args.speed:g}: expected {MIN_SPEED:g} to {MAX_SPEED:g}")
    path = Path(args.path)
    if args.to and path.suffix.lower() == ".tlog" and path.is_file():
        beside = path.parent / f"{path.stem}.expected.json"
        if not beside.exists():  # any tlog can be replayed into PX4, reproducer or not
            return _stream(path, args)
    try:
        reproducer = load(path)
    except ReproducerError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    recording = reproducer.recording
    try:
        unusable = recording_problem(reproducer)
    except SourceError as exc:  # the recording is not one fuzzoff can read (empty, foreign)
        print(f"fuzzoff: {printable(exc.line())}", file=sys.stderr)
        return 2
    if unusable is not None:
        print(f"error: {printable(unusable)}", file=sys.stderr)
        return 2
    if args.to:
        return _stream(recording, args)
    from fuzzoff.engine import lint_file
    from fuzzoff.fuzz.reproducers import expected_findings
    from fuzzoff.fuzz.scenario import Scenario

    scenario = reproducer.scenario or Scenario("1.15", "mc", "ros2", events=())
    report = lint_file(recording, scenario.settings(reproducer.rules))
    differ = compare(reproducer.findings, expected_findings(report))
    try:
        again = recheck(reproducer)
    except SourceError as exc:  # the recording is not one fuzzoff can read (empty, foreign)
        print(f"fuzzoff: {printable(exc.line())}", file=sys.stderr)
        return 2
    still = again.problems
    prop = reproducer.prop
    verdict = None if prop is None else "still fails" if still else "fixed"
    data = {
        "reproducer": str(args.path),
        "recording": str(recording),
        "property": prop,
        "findings_match": not differ,
        "finding_differences": differ,
        "verdict": verdict,
        "property_still_fails": bool(still),
        "rechecked_on": "stream" if again.on_stream else "recording",
        "problems": still,
        "setup": None if reproducer.setup is None else reproducer.setup.to_json(),
    }
    against = _against_block(reproducer.path)
    if against is not None:
        data["against"] = against
    if args.format == "json":
        text = json.dumps(data, indent=2) + "\n"
    else:
        text = _terminal(recording, prop, verdict, differ, still, again.on_stream)
        if reproducer.setup is not None:
            text += f"  on a live PX4: {reproducer.setup.describe()}\n"
        if against is not None:
            text += _against_text(against, args.path)
    write_output(text, args.output)
    return 1 if differ or still else 0


def _against_block(path: Path) -> dict[str, Any] | None:
    """The ``against`` object of a reproducer ``fuzzoff fuzz --against`` saved (what a real
    PX4 did beside the model), or None."""
    try:
        block = json.loads(path.read_text()).get("against")
    except (OSError, ValueError, AttributeError):
        return None
    return block if isinstance(block, dict) else None


def _against_text(against: dict[str, Any], path: str) -> str:
    differ = [d for d in against.get("differ", []) if isinstance(d, dict)]
    state = {True: "confirmed", False: "seen once", None: "unconfirmed"}.get(
        against.get("confirmed"), "unconfirmed"
    )
    lines = [
        f"  against PX4 {printable(str(against.get('px4')))} ({state}): it and the model differed"
    ]
    for d in differ:
        lines.append(
            f"    {printable(str(d.get('what')))}: PX4 {printable(str(d.get('px4')))};"
            f" model {printable(str(d.get('model')), 200)}"
        )
    if against.get("transport") == "ros2":
        lines.append(
            f"  send it to PX4 over DDS again: fuzzoff sitl replay {printable(path)}"
            f" --transport ros2 --release {printable(str(against.get('px4')))}"
        )
    else:
        lines.append(
            f"  send it to a running PX4 again: fuzzoff replay {printable(path)} --to"
            " udp:127.0.0.1:14580"
        )
    return "\n".join(lines) + "\n"


def _terminal(
    recording: Path,
    prop: str | None,
    verdict: str | None,
    differ: list[str],
    still: list[str],
    on_stream: bool,
) -> str:
    lines = [f"{printable(str(recording))}:"]
    lines.append("  findings: " + ("as expected" if not differ else "DIFFER"))
    lines += [f"    {d}" for d in differ]
    if prop:
        basis = "" if on_stream else " (checked on the recording's events: no stream saved)"
        lines.append(f"  property {prop}: {verdict}{basis}")
        lines += [f"    {printable(p, 300)}" for p in still]
    return "\n".join(lines) + "\n"


def _stream(recording: Path, args: argparse.Namespace) -> int:
    import tempfile

    from fuzzoff.commands._common import parse_params
    from fuzzoff.commands.sitl import report
    from fuzzoff.recording import SourceError
    from fuzzoff.sitl.link import LinkError
    from fuzzoff.sitl.run import replay_live
    from fuzzoff.sitl.target import TargetError, target_for

    try:
        target = target_for(args.to)
    except TargetError as exc:
        raise ConfigError(str(exc)) from None
    if recording.suffix.lower() != ".tlog":
        raise ConfigError(f"{recording}: --to streams MAVLink: only a .tlog reproducer")
    for name in ("connect_timeout", "ready_timeout"):
        value = getattr(args, name)
        if not 0 < value <= 3600:  # NaN too
            option = "--" + name.replace("_", "-")
            raise ConfigError(f"{option} {value:g}: expected more than 0 and at most 3600 s")
    params = parse_params(args.param)
    try:
        from fuzzoff.fuzz.reproducers import load

        loaded = load(Path(args.path))
        setup, cut = loaded.setup, loaded.cut_fraction
    except ReproducerError:
        setup, cut = None, None
    if cut is not None:
        print(
            f"fuzzoff: {printable(str(recording))} is the first {cut:.0%} of a recording (a"
            " truncation reproducer): PX4 gets that part only",
            file=sys.stderr,
        )
    manual = False
    if setup is not None:
        # The setup's PX4 parameters (not fuzzoff's own assumption FUZZOFF_RC_PRESENT, which
        # PX4 does not have: it is the joystick), the command line's win.
        params = {**setup.params, **params}
        manual = setup.manual_control
    record = (
        Path(args.record)
        if args.record
        else Path(tempfile.mkstemp(prefix="fuzzoff-replay-", suffix=".tlog")[1])
    )

    def log(line: str) -> None:
        print(f"fuzzoff: {printable(line)}", file=sys.stderr)

    try:
        outcome = replay_live(
            recording,
            (target.family, target.address),
            record,
            release=args.px4,
            params=params,
            speed=args.speed,
            connect_timeout=args.connect_timeout,
            ready_timeout=args.ready_timeout,
            log=log,
            manual=manual,
        )
    except (LinkError, SourceError) as exc:
        print(f"error: --to {target}: {printable(str(exc))}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"error: --to {args.to!r}: cannot send: {exc.strerror or exc}", file=sys.stderr)
        return 2
    return report(outcome, args.format, args.output)
