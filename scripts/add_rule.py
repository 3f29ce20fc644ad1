"""Scaffold a new rule, as ruff's ``scripts/add_rule.py`` does: the recipe of
docs/contributing.md ("Add a rule") as one command, so that it cannot drift from the code.

    .venv/bin/python scripts/add_rule.py OFB204 switch-before-stream --severity error
    make new-rule CODE=OFB204 NAME=switch-before-stream ARGS="--severity error"

It writes

* ``rules/CODE.toml``: the page, every key filled with a TODO to replace (the catalog loads it,
  so ``fuzzoff rule CODE`` shows it at once);
* ``fuzzoff/checks/MODULE.py``: a ``Check`` subclass with ``codes = ("CODE",)``, subscribed to
  the corpus's usual setpoint, reporting nothing yet (a module there registers itself);
* a bad and a good case in the corpus builder (``--corpus``: ``rules`` for the ROS 2 rules,
  ``rules_mavlink`` for MAVLink setpoint fields, ``rules_rover`` for the ROS 2 rover rules),
  inserted above the builder's ``add_rule.py`` marker: the good case lists the rule as
  ``clean``, the bad one expects it, both on the builder's realistic flight until edited;

then runs the builder (its recordings and ``expected.json`` files) and ``docs/rules/build.py``
(the page, the index, the overview tables). A rule that judges the keep-alive and setpoint
stream as the companion sent it (``--sent-stream``) gets ``sent_stream = true``: the engine does
not run it on a recording without that stream, and OFB002 names it there.

What is left is the rule itself, and the tests say where: the bad corpus case and the page's
bad test stream expect a finding the new check does not give yet (tests/test_corpora.py,
tests/test_catalog_examples.py). Write the check, make the bad case show the rule, fill the
page's TODOs, run the builder again, and update the ``expected.json`` of every other corpus
recording the rule fires in (docs/contributing.md says how).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

MARKER = "scripts/add_rule.py adds a new rule's cases above this line"
"""The comment in each corpus builder above which the new cases go."""

CODE = re.compile(r"^OFB\d{3}$")
NAME = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")
SEVERITIES = ("error", "warning", "info")


@dataclass(frozen=True, slots=True)
class Corpus:
    """A corpus builder that takes new rules, and what a new rule of it starts from."""

    folder: str
    event: str
    """The ``fuzzoff.events`` class the check skeleton subscribes to."""
    profiles: str
    """The page's ``profiles`` line."""
    stream_profile: str
    test_stream: tuple[str, ...]
    """The events of the page's test stream skeleton (TOML inline tables)."""
    cases: str
    """The builder's bad and good case, formatted with ``code``, ``slug``, ``severity``."""


ROS2_CASES = """\
    # {code} ({name})
    # TODO change one thing of the realistic flight so that the rule fires, at the time its
    # page says (the first setpoint after the switch is a placeholder).
    cases.append(
        Case(
            "{slug}",
            Flight(POSITION, climb).events(),
            [("{code}", "{severity}", SWITCH_T + 0.05)],
            [],
        )
    )
    cases.append(
        Case(
            "good_{slug}",
            Flight(POSITION, climb).events(),
            [],
            ["{code}"],
        )
    )
"""

MAVLINK_CASES = """\
        # {code} ({name})
        # TODO change the stream (or add a second one, ``flight``'s ``extra``) so that the rule
        # fires, at the time its page says (START is a placeholder).
        Case(
            "{slug}",
            "mc",
            flight("mc", local),
            [("{code}", "{severity}", START)],
            [],
            bag=False,
        ),
        Case(
            "good_{slug}",
            "mc",
            flight("mc", local),
            [],
            ["{code}"],
            bag=False,
        ),
"""

ROVER_CASES = """\
        # {code} ({name})
        # TODO change one thing of the drive so that the rule fires, at the time its page says
        # (the first setpoint is a placeholder).
        Case(
            "{slug}",
            "rover-differential",
            Drive({{"velocity": True}}, speed_attitude),
            [("{code}", "{severity}", FIRST_SETPOINT)],
            [],
        ),
        Case(
            "good_{slug}",
            "rover-differential",
            Drive({{"velocity": True}}, speed_attitude),
            [],
            ["{code}"],
        ),
"""

CORPORA: dict[str, Corpus] = {
    "rules": Corpus(
        folder="rules",
        event="TrajectorySetpoint",
        profiles='{ px4 = ["all"], vehicles = ["all"] }',
        stream_profile='{ px4 = "1.15", vehicle = "mc" }',
        test_stream=(
            '{ kind = "control_mode", t = 0.0, position = true }',
            '{ kind = "vehicle_status", t = 0.0, nav_state = 14, armed = true }',
            '{ kind = "trajectory", t = 0.05, position = [0.0, 0.0, -2.0] }',
        ),
        cases=ROS2_CASES,
    ),
    "rules_mavlink": Corpus(
        folder="rules_mavlink",
        event="SetPositionTargetLocal",
        profiles='{ px4 = ["all"], vehicles = ["all"] }',
        stream_profile='{ px4 = "1.16", vehicle = "mc" }',
        test_stream=(
            '{ kind = "vehicle_status", t = 0.0, vehicle = "1", nav_state = 14, armed = true }',
            '{ kind = "set_position_target_local_ned", t = 0.1, vehicle = "1", '
            "target_system = 1, target_component = 1, type_mask = 3576, "
            "coordinate_frame = 1 }",
        ),
        cases=MAVLINK_CASES,
    ),
    "rules_rover": Corpus(
        folder="rules_rover",
        event="RoverSpeedSetpoint",
        profiles='{ px4 = ["1.16+"], vehicles = ["rover"] }',
        stream_profile='{ px4 = "1.17", vehicle = "rover-differential" }',
        test_stream=(
            '{ kind = "control_mode", t = 0.0, velocity = true }',
            '{ kind = "vehicle_status", t = 0.0, nav_state = 14, armed = true }',
            '{ kind = "rover_speed", t = 0.05, speed_body_x = 1.0 }',
        ),
        cases=ROVER_CASES,
    ),
}


def default_corpus(code: str) -> str:
    """The builder most rules of the code's family use: OFB5xx the rover one, OFB6xx the
    MAVLink one, the others the ROS 2 one."""
    if code.startswith("OFB5"):
        return "rules_rover"
    if code.startswith("OFB6"):
        return "rules_mavlink"
    return "rules"


class ScaffoldError(Exception):
    """The rule cannot be scaffolded as asked (a code or name taken, a builder without marker)."""


# -- the files --------------------------------------------------------------------------------


def page(code: str, name: str, severity: str, corpus: Corpus, sent_stream: bool) -> str:
    """``rules/CODE.toml``: every key docs/contributing.md lists, each a TODO that loads."""
    stream = ",\n".join(f"  {event}" for event in corpus.test_stream)
    flag = "sent_stream = true\n" if sent_stream else ""
    return f'''\
code = "{code}"
name = "{name}"
severity = "{severity}"
{flag}profiles = {corpus.profiles}
# formats = ["tlog"]  # TODO the formats whose recordings can show the rule (none: all)
# explains = []  # TODO the gate outcomes a finding explains (catalog.HAZARD_KINDS), if any
summary = """
TODO: what the rule flags, in one paragraph: which messages, in which mode, from when.
"""
why = """
TODO: what the vehicle does when a client breaks the rule, concretely.
"""
docs_vs_code = """
TODO: where PX4's code does otherwise than its docs say (or remove this key).
"""

[example]
client = "TODO: the client library and release (rclpy with px4_msgs, MAVSDK, MAVROS, pymavlink)"
language = "python"
bad = \'\'\'
# TODO: the smallest client code that breaks the rule
pass
\'\'\'
good = \'\'\'
# TODO: the same code, fixed
pass
\'\'\'

# TODO: bad must give {code}, good must not (tests/test_catalog_examples.py replays both)
[test_stream]
profile = {corpus.stream_profile}
bad = [
{stream},
]
good = [
{stream},
]

[[references]]
title = "TODO: PX4 User Guide, the page and section the rule follows"
url = "https://docs.px4.io/main/en/flight_modes/offboard.html"
'''


def class_name(name: str) -> str:
    return "".join(part.capitalize() for part in name.split("-"))


def check(code: str, name: str, corpus: Corpus) -> str:
    """``fuzzoff/checks/MODULE.py``: a registered check that reports nothing yet."""
    return f'''\
"""{code} ({name}).

TODO: what the check judges, and the PX4 source (file at a tag) or the docs section it follows.
"""

from __future__ import annotations

from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import Event, {corpus.event}


class {class_name(name)}(Check):
    """{code}: TODO one line on what is reported, once per what."""

    codes = ("{code}",)
    wants = ({corpus.event},)
    """TODO the event types the rule judges (``GateTransition`` for the gate's outcomes)."""

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)

    def on_event(self, event: Event) -> None:
        """TODO: the condition. ``self.ctx.flying`` / ``self.ctx.in_offboard`` say the mode (the
        recorded one, else the gate's prediction), ``self.ctx.gate`` is the gate model."""
        if not self.ctx.flying:
            return
        # self.ctx.report("{code}", "what happened and what PX4 does", event.t, event.where)

    def finish(self, t_end: float) -> None:
        """TODO: report what is still open at the end of the recording, or remove."""
'''


def insert_cases(builder: Path, text: str) -> None:
    """Put ``text`` above the builder's marker line."""
    source = builder.read_text(encoding="utf-8")
    lines = source.splitlines(keepends=True)
    at = [i for i, line in enumerate(lines) if MARKER in line]
    if len(at) != 1:
        raise ScaffoldError(f"{builder}: no line (or several) saying '# -- {MARKER}'")
    lines[at[0] : at[0]] = [text]
    builder.write_text("".join(lines), encoding="utf-8")


# -- the command ------------------------------------------------------------------------------


def _python(root: Path, script: Path) -> None:
    """Run a script of the repository at ``root`` with that repository's fuzzoff first."""
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")])),
    }
    subprocess.run(
        [sys.executable, str(script)], cwd=root, env=env, check=True, stdout=subprocess.DEVNULL
    )


def add_rule(
    root: Path,
    code: str,
    name: str,
    *,
    severity: str = "warning",
    corpus_name: str | None = None,
    module: str | None = None,
    sent_stream: bool = False,
    build: bool = True,
) -> list[Path]:
    """Write the new rule's files in the repository at ``root``; the paths written, in order."""
    code = code.upper()
    if not CODE.match(code):
        raise ScaffoldError(f"{code!r} is not a rule code (OFB and three digits)")
    if not NAME.match(name):
        raise ScaffoldError(f"{name!r} is not a rule name (lower-case words joined by '-')")
    if severity not in SEVERITIES:
        raise ScaffoldError(f"severity {severity!r}: one of {', '.join(SEVERITIES)}")
    corpus = CORPORA[corpus_name or default_corpus(code)]
    rules = root / "rules"
    rule_page = rules / f"{code}.toml"
    if rule_page.exists():
        raise ScaffoldError(f"{rule_page.relative_to(root)} exists: {code} is taken")
    quoted = f'name = "{name}"\n'
    for other in sorted(rules.glob("OFB*.toml")):
        if quoted in other.read_text(encoding="utf-8"):
            raise ScaffoldError(f"{other.name} already has the name {name!r}")
    check_module = root / "fuzzoff" / "checks" / f"{module or name.replace('-', '_')}.py"
    if check_module.exists():
        raise ScaffoldError(f"{check_module.relative_to(root)} exists: choose another --module")
    builder = root / "corpora" / corpus.folder / "build.py"
    slug = f"{code.lower()}_{name.replace('-', '_')}"
    cases = corpus.cases.format(code=code, name=name, slug=slug, severity=severity)
    insert_cases(builder, cases)  # first: a builder without its marker leaves nothing behind
    rule_page.write_text(page(code, name, severity, corpus, sent_stream), encoding="utf-8")
    check_module.write_text(check(code, name, corpus), encoding="utf-8")
    written = [rule_page, check_module, builder]
    if build:
        _python(root, builder)
        _python(root, root / "docs" / "rules" / "build.py")
        written += [
            builder.parent / f"{slug}.expected.json",
            builder.parent / f"good_{slug}.expected.json",
            root / "docs" / "rules" / f"{code}.md",
        ]
    return written


NEXT_STEPS = """\
next:
  1. {check}: the condition and the report (the tests list what the page says)
  2. {page}: replace every TODO (summary, why, example, test stream, references)
  3. {builder}: make the bad case show {code} (it is the good flight until then), run it again
  4. the expected.json of every other corpus recording {code} fires in (docs/contributing.md)
  5. .venv/bin/python docs/rules/build.py, then make check and the tests"""


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="scripts/add_rule.py",
        description="Scaffold a new rule: its page, its check, its corpus cases, the docs.",
    )
    parser.add_argument("code", help="the new rule's code, e.g. OFB204")
    parser.add_argument("name", help="its name: lower-case words joined by '-'")
    parser.add_argument("--severity", default="warning", choices=SEVERITIES)
    parser.add_argument(
        "--corpus",
        choices=sorted(CORPORA),
        help="the corpus builder of its cases (default: by family, OFB5 rules_rover, "
        "OFB6 rules_mavlink, else rules)",
    )
    parser.add_argument(
        "--module", help="the check's module in fuzzoff/checks (default: the name with '_')"
    )
    parser.add_argument(
        "--sent-stream",
        action="store_true",
        help="the rule judges the stream as sent: off on recordings without it",
    )
    parser.add_argument(
        "--no-build", action="store_true", help="write the files only: run neither builder"
    )
    parser.add_argument("--root", type=Path, default=ROOT, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    root: Path = args.root.resolve()
    try:
        written = add_rule(
            root,
            args.code,
            args.name,
            severity=args.severity,
            corpus_name=args.corpus,
            module=args.module,
            sent_stream=args.sent_stream,
            build=not args.no_build,
        )
    except ScaffoldError as exc:
        print(f"add_rule: {exc}", file=sys.stderr)
        return 2
    for path in written:
        print(f"wrote {path.relative_to(root)}")
    rule_page, check_module, builder = (p.relative_to(root) for p in written[:3])
    print(
        NEXT_STEPS.format(
            check=check_module, page=rule_page, builder=builder, code=args.code.upper()
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
