"""Write ``NAME.expected.json`` for every recording in ``runs.json``: what ``fuzzoff lint`` says
about it now, with what the recording is.

    .venv/bin/python -m corpora.sitl.expected

The findings are today's output, so that ``tests/test_corpora.py`` notices any change. Findings
that are not true of a recording are not blessed silently: each expected file lists them under
``known_false`` with the issue that fixes them, and ``tests/test_real_world_precision.py``
holds the acceptance (clean recordings exit 0, hazards give their error) as strict xfails until
the fix lands. Rerun this script after a rule or reader change and review the difference.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from fuzzoff.commands.replay import compare
from fuzzoff.sitl.scenarios import SCENARIOS
from tests.helpers import run_cli

HERE = Path(__file__).resolve().parent

KNOWN_FALSE: dict[str, str] = {
    "OFB001": "issue 17: a PX4 tlog holds MAVLink 'development' ids (8, 380, 410, 411, 436)"
    " that the 'common' dialect lacks: ordinary traffic, not unreadable input",
    "OFB107": "issue 17: OFB107 warns on every hold (a held position is what a stopped"
    " controller should leave)",
    "OFB404": "issue 17: OFB404 on PX4's own trajectory_setpoint before the switch, or on a"
    " first descent after a takeoff",
    "OFB702": "issue 17: OFB702 warns on every flight without RC although no loss happened",
    "OFB102": "issue 17: OFB102 on the documented set-then-start pattern (MAVSDK) or one"
    " setpoint before the switch, which PX4 accepts",
    "OFB101": "issue 17: OFB101 after the switch away from offboard (the accepted ack ends"
    " the window)",
    "OFB103": "issue 18: the ULog's first offboard_control_mode samples are missing (logger),"
    " so the model sees no keep-alive PX4 had",
    "OFB202": "issue 18: the same missing ULog samples make the model disagree with PX4",
    "OFB201": "issue 17: the ULog's missing first samples make the switch look unstreamed",
    "OFB401": "issue 17: a ULog's trajectory_setpoint also holds PX4's own setpoints (its"
    " flight tasks in its own modes), not the client's",
    "OFB105": "issue 17: OFB105 judges a keep-alive's jitter PX4 does not act on",
}
"""Rule -> why its finding on a *clean* recording is false (the rule helper's and the readers
helper's fixes, issue 17/18). Hazard recordings keep all their findings as true."""


DISARM_DENIED = (
    "issue 18: the model accepts a disarm in flight that PX4 refuses ('Disarming denied: not"
    " landed'), and OFB202 then calls it an arm"
)


MISSED_SAMPLES = (
    "issue 18: the logger missed the ULog's first offboard_control_mode samples (the switch"
    " came 10-50 ms after the first setpoint), so the model sees no keep-alive PX4 had; PX4's"
    " failsafe_flags.offboard_control_signal_lost says it had one"
)


def _missed_first_samples(findings: list[dict[str, Any]]) -> bool:
    """The ULog's logger missed the first keep-alive samples: the model sees no keep-alive
    while in OFFBOARD, or rejects a switch the ULog shows accepted for want of one."""
    return any(
        (f["code"] == "OFB103" and "no keep-alive while in OFFBOARD" in f["message"])
        or (
            f["code"] == "OFB202"
            and "switch to OFFBOARD acked ACCEPTED" in f["message"]
            and "model: rejected (no offboard signal)" in f["message"]
        )
        for f in findings
    )


def why_false(finding: dict[str, Any], findings: list[dict[str, Any]]) -> str:
    if finding["code"] == "OFB202" and "arm acked TEMPORARILY_REJECTED" in finding["message"]:
        return DISARM_DENIED
    unseen = _missed_first_samples(findings)
    if unseen and finding["code"] in ("OFB102", "OFB103", "OFB202", "OFB702"):
        return MISSED_SAMPLES
    return KNOWN_FALSE.get(finding["code"], "to review")


MAVSDK_PROGRAMS: dict[str, tuple[str, list[str], str, str]] = {
    "offboard": (
        "clean",
        [],
        "cpp/examples/offboard sequence",
        "MAVSDK offboard example: attitude, then velocity NED",
    ),
    "actuator": (
        "hazard",
        ["OFB608", "OFB103"],
        "offboard velocity, then set_actuator_control",
        "MAVSDK hovers in offboard on a velocity setpoint, then calls set_actuator_control",
    ),
}
"""``record_mavsdk.py --program`` -> (kind, hazard codes, what the client does, what the run is)."""

MAVSDK_HAZARDS = {
    "actuator": "SET_ACTUATOR_CONTROL_TARGET at 40 Hz, which PX4 1.14+ ignores: the keep-alive"
    " stops, loss failsafe"
}


def _first_loss(findings: list[dict[str, Any]]) -> float:
    """When the first loss failsafe came (the hazard's own findings start there)."""
    return min((f["time_s"] for f in findings if f["code"] == "OFB103"), default=float("inf"))


CONTEXT_UNSEEN = "the hazard cannot be seen in this recording (PX4 logged nothing of it)"
CONTEXT_RELEASE = "this release does what the program means: no hazard here"


def classify(stem: str, suffix: str = "") -> tuple[str, list[str], str]:
    """(kind, the hazard's error codes, what program wrote it). ``kind`` is ``context`` for a
    hazard program's recording that cannot show the hazard (``Scenario.shown_in``) or of a
    release where it is none (``Scenario.hazard_until``): counted neither clean nor hazard."""
    scenario_name = stem.split("-")[0]
    if scenario_name.startswith("mavsdk"):
        version, _, program = scenario_name[len("mavsdk") :].partition("_")
        kind, codes, client, _ = MAVSDK_PROGRAMS[program]
        return kind, list(codes), f"MAVSDK {version}.x (PyPI mavsdk), {client}"
    scenario = SCENARIOS[scenario_name]
    kind = scenario.kind
    if kind == "hazard" and context_of(stem, suffix) is not None:
        kind = "context"
    return (
        kind,
        list(scenario.codes),
        f"fuzzoff.sitl.scenarios.{scenario.program.__name__} (pymavlink)",
    )


def context_of(stem: str, suffix: str) -> str | None:
    """Why a hazard program's recording is context, not a hazard (None: it is a hazard)."""
    name, _, release = stem.partition("-")
    scenario = SCENARIOS.get(name)
    if scenario is None:
        return None
    if suffix and suffix not in scenario.shown_in:
        return CONTEXT_UNSEEN
    base = release.split("-")[0]
    # a build of main (main-2026-08-13) is past every 1.x release
    major, minor = (int(p) for p in base.split(".")[:2]) if base[:1].isdigit() else (999, 0)
    if scenario.hazard_until is not None and (major, minor) >= scenario.hazard_until:
        return CONTEXT_RELEASE
    return None


def expected_for(recording: Path, release: str) -> dict[str, Any]:
    stem = recording.name.rsplit(".", 1)[0]
    kind, codes, program = classify(stem, recording.suffix)
    out = run_cli(["lint", str(recording), "--format", "json"])
    data = json.loads(out.stdout)
    (report,) = data["files"]
    findings = [
        {"code": f["code"], "severity": f["severity"], "time_s": f["time_s"]}
        | ({"vehicle": f["vehicle"]} if f.get("vehicle") else {})
        for f in report["findings"]
    ]
    spec: dict[str, Any] = {
        "recording": recording.name,
        "args": [],
        "exit_status": out.returncode,
        "complete": report["complete"],
        "kind": kind,
        "hazard": codes,
        "program": program,
        "px4_release": release,
        "findings": findings,
    }
    if kind == "context":
        spec["context"] = context_of(stem, recording.suffix)
    if kind == "clean":
        spec["known_false"] = sorted(
            {
                f"{f['code']} {f['severity']}: {why_false(f, report['findings'])}"
                for f in report["findings"]
                if f["severity"] in ("warning", "error")
            }
        )
    elif recording.suffix == ".tlog":
        spec["known_false"] = sorted(
            {
                f"{f['code']} {f['severity']}: {KNOWN_FALSE[f['code']]}"
                for f in report["findings"]
                if f["code"] == "OFB001"
            }
        )
    elif _missed_first_samples(report["findings"]):
        # a hazard's own findings are true; those the logger's missed samples made are not
        spec["known_false"] = sorted(
            {
                f"{f['code']} {f['severity']}: {MISSED_SAMPLES}"
                for f in report["findings"]
                if f["code"] in ("OFB102", "OFB202")
                and f["severity"] in ("warning", "error")
                and f["time_s"] is not None
                and f["time_s"] < _first_loss(report["findings"])
            }
        )
    assert not compare(findings, report["findings"])
    return spec


README_HEAD = """# Real PX4 SITL runs

Recordings written by real PX4 (its own ULog) and by real clients on its offboard link (the
tlog of both directions), on the PX4 SITL bundles of `../shared/px4-sitl/` (SIH quadrotor;
`hex_*`, `vtol_*`, `tailsitter_*`, `fw_*` and `rover_*` the SIH hexacopter, standard VTOL,
tailsitter, airplane and Ackermann rover, whose ULogs keep PX4's fastest estimator and
controller topics at 10 Hz; PX4's default parameters but those a scenario sets, listed per run
in `runs.json`: the tailsitter's airspeed use and right elevon, the airplane's outputs in
`fw_gate`, its outputs, thrust and (1.14, 1.15) elevator sign and lift-off pitch in
`fw_offboard` and `fw_loss`, with `SIH_LOC_H0` 0 set at boot (`boot_params`), the stick
override; no RC). Each run boots a fresh PX4.

- `NAME-RELEASE.tlog`: the exchange as the client saw it, on PX4's clock (`docs/sitl.md`);
- `NAME-RELEASE.ulg`: PX4's log from boot to exit, cut with pyulog to the topics fuzzoff reads
  (`fuzzoff/sitl/trim.py`, as `corpora/real/cut.py` does);
- `NAME-RELEASE.{tlog,ulg}.expected.json`: today's findings (`tests/test_corpora.py`), what the
  recording is (`kind`, `hazard`, `program`, `px4_release`), and `known_false`: findings that are
  not true of a clean recording, with the issue that fixes them (never blessed silently);
- `runs.json`: each run's steps with PX4's time and PX4's answer.

Written by `record.py` (pymavlink scenario programs, `fuzzoff/sitl/scenarios.py`) and
`record_mavsdk.py` (real MAVSDK from PyPI, 3.x with its `mavsdk_server` and 4.x native, flying
`mavsdk_offboard.py`, the sequence of MAVSDK's `cpp/examples/offboard`, or `mavsdk_actuator.py`,
`set_actuator_control` in offboard, through `fuzzoff/sitl/proxy.py`; their ULogs leave out
`vehicle_local_position` to stay under 1 MB); the expected files by `expected.py`, the
model-vs-PX4 table in `docs/sitl.md` by `agreement.py`. *clean*: a correct use of offboard,
fuzzoff should find nothing at warning or above. *hazard*: fuzzoff should give the error named.
*context*: a hazard program's recording that cannot show the hazard (a ULog holds no command
PX4's receiver dropped) or of a release where it is none; counted neither way. The pymavlink
programs stream at 10 Hz and pause while they wait for an ack (up to about 0.25 s around a
switch or an arm); MAVSDK streams at 20 Hz throughout and sends each new setpoint at once.

| recording | program | PX4 | what it is | lint today |
| --- | --- | --- | --- | --- |
"""


def readme_rows(runs: dict[str, Any]) -> list[str]:
    rows = []
    for stem, run in sorted(runs.items()):
        scenario = SCENARIOS.get(stem.split("-")[0])
        mavsdk = stem.split("-")[0].partition("_")[2]
        what = scenario.summary if scenario else MAVSDK_PROGRAMS[mavsdk][3]
        hazard = scenario.hazard if scenario else MAVSDK_HAZARDS.get(mavsdk, "")
        for suffix in (".tlog", ".ulg"):
            spec_path = HERE / f"{stem}{suffix}.expected.json"
            if not spec_path.exists():
                continue
            kind, codes, program = classify(stem, suffix)
            label = "clean" if kind == "clean" else f"hazard {'/'.join(codes)}: {hazard}"
            if kind == "context":
                label = f"context: {context_of(stem, suffix)}"
            spec = json.loads(spec_path.read_text())
            loud = sorted(
                {
                    f"{f['code']} {f['severity']}"
                    for f in spec["findings"]
                    if f["severity"] != "info"
                }
            )
            today = f"exit {spec['exit_status']}" + (f": {', '.join(loud)}" if loud else "")
            rows.append(
                f"| `{stem}{suffix}` | {program.split(' (')[0]} | {run['release']} | {what};"
                f" **{label}** | {today} |"
            )
    return rows


def main() -> None:
    runs = json.loads((HERE / "runs.json").read_text())
    for stem, run in sorted(runs.items()):
        for suffix in (".tlog", ".ulg"):
            recording = HERE / f"{stem}{suffix}"
            if not recording.exists():
                continue
            spec = expected_for(recording, run["release"])
            target = HERE / f"{stem}{suffix}.expected.json"
            target.write_text(json.dumps(spec, indent=2) + "\n")
            print(f"{target.name}: exit {spec['exit_status']}, {len(spec['findings'])} findings")
    (HERE / "README.md").write_text(README_HEAD + "\n".join(readme_rows(runs)) + "\n")


if __name__ == "__main__":
    main()
