"""Write ``NAME.expected.json`` for every recording of ``runs.json``: what ``fuzzoff lint``
says about it now, with what the recording is; and ``BAG.with.expected.json`` for each bag
linted with its flight's ULog (``--with``: OFB108 on the agent restart and the lost ARM, clean
of it on every other flight).

    PYTHONPATH=. .venv/bin/python corpora/ros2bridge/expected.py

As ``corpora/sitl/expected.py``: the findings are today's output (``tests/test_corpora.py``
notices any change); a warning or error on a *clean* recording is listed under ``known_false``
(to review with the rule's owner, never blessed silently), and a *hazard* recording whose error
fuzzoff does not give lists why under ``missed``. ``tests/test_ros2_bridge_corpus.py`` holds the
acceptance (clean: exit 0; hazard: its error; both storages alike).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent))

from fuzzoff.catalog import get_rule  # noqa: E402
from fuzzoff.commands.replay import compare  # noqa: E402
from fuzzoff.sitl.ros2.programs import PROGRAMS  # noqa: E402
from tests.helpers import run_cli  # noqa: E402

RECORDINGS = ("-mcap", "-sqlite3", ".ulg")
"""The three recordings of one flight: the bag in both storages, PX4's ULog."""
NOT_IN_ULOG = {
    "OFB203": "a ULog's trajectory_setpoint holds PX4's own setpoints in its own modes beside"
    " the client's, so OFB203 is not checkable there (OFB002 says so); the bags show it",
    "OFB208": "a command that never reached PX4 leaves no trace in its ULog (its vehicle_command"
    " holds what PX4 received); the bags show it",
    **{
        code: "a ULog's rover setpoint and trajectory_setpoint topics hold PX4's own setpoints"
        " beside the client's (the rover modules write them), so the rover rules are not"
        " checkable there (OFB002 says so); the bags show it"
        for code in ("OFB501", "OFB502", "OFB503", "OFB510")
    },
    "OFB209": "PX4's default log profile does not log the external-mode registration and"
    " arming-check topics; the bags show them",
}
"""Hazard code -> why PX4's ULog cannot show it."""


def expected_for(recording: Path, run: dict[str, Any]) -> dict[str, Any]:
    program = PROGRAMS[run["program"]]
    out = run_cli(["lint", str(recording), *program.lint_args, "--format", "json"])
    (report,) = json.loads(out.stdout)["files"]
    findings = [
        {"code": f["code"], "severity": f["severity"], "time_s": f["time_s"]}
        | ({"vehicle": f["vehicle"]} if f.get("vehicle") else {})
        for f in report["findings"]
    ]
    spec: dict[str, Any] = {
        "recording": recording.name,
        "args": list(program.lint_args),
        "exit_status": out.returncode,
        "complete": report["complete"],
        "profile": {
            "px4": report["profile"]["px4"],
            "vehicle": report["profile"]["vehicle"],
            "detected": report["profile"]["detected"],
        },
        "kind": program.kind,
        "hazard": list(program.codes),
        "program": f"fuzzoff.sitl.ros2.programs {program.name}: {program.summary}",
        "px4_release": run["release"],
        "findings": findings,
    }
    if program.notes:
        spec["notes"] = program.notes
    if program.kind == "clean":
        why = program.missed or "to review"
        spec["known_false"] = sorted(
            {
                f"{f['code']} {f['severity']}: {why} ({f['message']})"
                for f in report["findings"]
                if f["severity"] in ("warning", "error")
            }
        )
    elif not any(
        f["code"] in program.codes and f["severity"] == get_rule(f["code"]).severity.label
        for f in report["findings"]
    ):
        why = [
            NOT_IN_ULOG[c] for c in program.codes if recording.suffix == ".ulg" and c in NOT_IN_ULOG
        ]
        spec["missed"] = why or [
            f"{program.missed or 'to review'}: fuzzoff does not give the hazard's error"
        ]
    assert not compare(findings, report["findings"])
    return spec


WITH_HAZARD = {"example_agent_restart": ("OFB108",), "example_arm_lost": ("OFB108",)}
"""Program -> what ``lint BAG --with ULOG`` adds to its hazard (the bag and PX4's ULog compared);
every other flight lists OFB108 as ``clean``."""


def with_expected(bag: Path, ulog: Path, run: dict[str, Any]) -> dict[str, Any]:
    """``NAME.with.expected.json``: the bag linted with its flight's ULog (``--with``, the path
    from the repository's root, where the tests run)."""
    program = PROGRAMS[run["program"]]
    args = [*program.lint_args, "--with", str(ulog.relative_to(HERE.parent.parent))]
    out = run_cli(["lint", str(bag), "--format", "json", *args])
    assert out.returncode in (0, 1), out.stderr
    (report,) = json.loads(out.stdout)["files"]
    findings = [
        {"code": f["code"], "severity": f["severity"], "time_s": f["time_s"]}
        for f in report["findings"]
    ]
    hazard = WITH_HAZARD.get(program.name, ())
    spec: dict[str, Any] = {
        "recording": bag.name,
        "args": args,
        "exit_status": out.returncode,
        "complete": report["complete"],
        "kind": program.kind,
        "hazard": sorted({*program.codes, *hazard}),
        "program": f"fuzzoff.sitl.ros2.programs {program.name}: {program.summary}",
        "px4_release": run["release"],
        "findings": findings,
    }
    if not hazard:
        spec["clean"] = ["OFB108"]
    got = {f["code"] for f in report["findings"] if f["severity"] == "error"}
    assert set(hazard) <= got and ("OFB108" in got) == bool(hazard), (bag, got)
    if program.kind == "hazard" and not got & set(spec["hazard"]):
        spec["missed"] = [f"{program.missed or 'to review'}: no error of {spec['hazard']}"]
    assert not compare(findings, report["findings"])
    return spec


TABLE = "<!-- the table is written by expected.py -->"


def row(spec: dict[str, Any]) -> str:
    errors = sorted({f["code"] for f in spec["findings"] if f["severity"] == "error"})
    warnings = sorted({f["code"] for f in spec["findings"] if f["severity"] == "warning"})
    lint = f"exit {spec['exit_status']}"
    lint += f", errors {' '.join(errors)}" if errors else ""
    lint += f", warnings {' '.join(warnings)}" if warnings else ""
    if spec.get("missed") or spec.get("known_false"):
        lint += " (see `missed`/`known_false`)"
    program = spec["program"].split(":")[0].split()[-1]
    return (
        f"| `{spec['recording']}` | {program} | {spec['px4_release']} | {spec['profile']['px4']}"
        f" | {spec['kind']} | {lint} |"
    )


def main() -> int:
    runs: dict[str, dict[str, Any]] = json.loads((HERE / "runs.json").read_text())
    rows = []
    for stem, run in sorted(runs.items()):
        for suffix in RECORDINGS:
            recording = HERE / f"{stem}{suffix}"
            spec = expected_for(recording, run)
            target = HERE / f"{recording.name}.expected.json"
            target.write_text(json.dumps(spec, indent=2) + "\n")
            rows.append(row(spec))
            print(f"{target.name}: exit {spec['exit_status']}, {len(spec['findings'])} findings")
        for suffix in RECORDINGS[:2]:
            bag = HERE / f"{stem}{suffix}"
            spec = with_expected(bag, HERE / f"{stem}.ulg", run)
            target = HERE / f"{bag.name}.with.expected.json"
            target.write_text(json.dumps(spec, indent=2) + "\n")
            print(f"{target.name}: exit {spec['exit_status']}, {len(spec['findings'])} findings")
    readme = HERE / "README.md"
    head, _, rest = readme.read_text().partition(TABLE)
    _, _, tail = rest.partition(TABLE)
    header = "| recording | program | PX4 bundle | detected | kind | lint today |\n"
    header += "| --- | --- | --- | --- | --- | --- |\n"
    readme.write_text(f"{head}{TABLE}\n{header}" + "\n".join(rows) + f"\n{TABLE}{tail}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
