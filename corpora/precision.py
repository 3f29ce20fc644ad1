"""The README's precision table: what fuzzoff says on recordings real programs wrote.

``.venv/bin/python corpora/precision.py`` prints the table from the corpus's expected findings
(each replayed against today's ``fuzzoff lint`` by ``tests/test_examples_corpus.py``,
``tests/test_real_world_precision.py`` and ``tests/test_corpora.py``) and from the gate
model run on each recorded SITL exchange against PX4's own log (``fuzzoff.sitl.verdict``,
as ``tests/test_sitl.py`` runs it). ``tests/test_readme.py`` fails when the README's copy
differs from what this prints.
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

CORPORA = Path(__file__).resolve().parent
LOUD = ("warning", "error")


@dataclass(frozen=True)
class Row:
    recordings: str
    what: str
    clean: int
    loud_on_clean: int
    hazards: int
    caught: int
    gate: str = "-"
    """The gate model against PX4's ULog on the row's SITL runs: items agreed / judged."""


def _expected(path: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(path.read_text())
    return data


def _loud(spec: dict[str, Any]) -> int:
    return sum(f["severity"] in LOUD for f in spec["findings"])


def _errors(spec: dict[str, Any]) -> set[str]:
    return {f["code"] for f in spec["findings"] if f["severity"] == "error"}


def examples_row() -> Row:
    """The official examples as their sources send them; a hazard is named ``hazard_*``
    and caught when it gives an error (its rule: ``tests/test_examples_corpus.py``)."""
    specs = sorted((CORPORA / "examples").glob("*.expected.json"))
    clean = [_expected(p) for p in specs if not p.name.startswith("hazard_")]
    hazards = [_expected(p) for p in specs if p.name.startswith("hazard_")]
    return Row(
        "`corpora/examples/`",
        "official examples reproduced from their sources (px4_ros_com C++ and Python, MAVROS"
        " `offb_node` ROS 1 and ROS 2, px4-ros2-interface-lib, a ten-minute hold, a takeoff"
        " then offboard, a rover), PX4's side from real SITL runs",
        len(clean),
        sum(map(_loud, clean)),
        len(hazards),
        sum(bool(_errors(h)) for h in hazards),
    )


VEHICLE_ROWS = {
    "quad": "quadrotor (`sihsim_quadx`)",
    "hex": "hexacopter (`sihsim_hex`)",
    "vtol": "standard VTOL (`sihsim_standard_vtol`): MC, transition to FW in OFFBOARD, FW",
    "tailsitter": "tailsitter VTOL (`sihsim_xvert`, FW_USE_AIRSPD 0, the right elevon's torques"
    " of the 1.18 airframe): MC, transition, FW",
    "fw": "airplane (`sihsim_airplane`): runway takeoff, then OFFBOARD in the air; the gate on"
    " the ground (`fw_gate`) on every bundle; the takeoff setpoint type on the ground"
    " (`fw_takeoff_type`)",
    "rover-ackermann": "Ackermann rover (`sihsim_rover_ackermann`)",
}
"""The SITL vehicles, one row each (``fuzzoff.sitl.airframes``)."""


def _vehicle_of(spec: dict[str, Any]) -> str:
    from fuzzoff.sitl.scenarios import SCENARIOS

    scenario = SCENARIOS.get(spec["recording"].split("-")[0])
    return scenario.vehicle if scenario is not None else "quad"  # MAVSDK: the quadrotor


def sitl_rows(gate: Counter[tuple[str, str, bool | None]]) -> list[Row]:
    """One row per vehicle flown: ``sitl_row`` of its recordings, with its gate agreement."""
    specs = [_expected(p) for p in sorted((CORPORA / "sitl").glob("*.expected.json"))]
    rows = []
    for vehicle, what in VEHICLE_ROWS.items():
        mine = [s for s in specs if _vehicle_of(s) == vehicle]
        if mine:
            agree = sum(n for (v, _, ok), n in gate.items() if v == vehicle and ok)
            judged = sum(n for (v, _, ok), n in gate.items() if v == vehicle and ok is not None)
            rows.append(replace(sitl_row(mine, what), gate=f"{agree}/{judged}"))
    return rows


def sitl_row(specs: list[dict[str, Any]], vehicle: str) -> Row:
    """PX4 SITL's own ULogs and the offboard link's tlogs; a hazard is caught when one of
    the codes its expected file names is an error."""
    clean = [s for s in specs if s["kind"] == "clean"]
    hazards = [s for s in specs if s["kind"] == "hazard"]
    releases = sorted({s["px4_release"] for s in specs}, key=_release_key)
    mavsdk = any(s["recording"].startswith("mavsdk") for s in specs)
    return Row(
        "`corpora/sitl/`",
        f"{vehicle}, real PX4 SITL {', '.join(releases)}: its ULog and the tlog of its offboard"
        " link, flown by pymavlink scenario programs"
        + (" and real MAVSDK 3 and 4" if mavsdk else ""),
        len(clean),
        sum(map(_loud, clean)),
        len(hazards),
        sum(bool(_errors(h) & set(h["hazard"])) for h in hazards),
    )


WITH = ".with.expected.json"
"""A bag linted with its flight's ULog (``lint --with``)."""


def ros2bridge_rows(gate: Counter[tuple[str, str, bool | None]]) -> list[Row]:
    """PX4 over its ROS 2 bridge: the companion's bags (mcap and sqlite3, bytes as received) and
    PX4's ULog of each flight, each linted alone; a hazard is caught when one of the codes its
    expected file names is an error (a ULog cannot show a command that never reached PX4 or the
    client's setpoints through PX4's own modes; the agent restart needs the bag and the ULog
    together: the second row, each bag linted ``--with`` its ULog). The gate model runs on each
    flight's bag against PX4's ULog (``fuzzoff.sitl.ros2.verdict``)."""
    every = sorted((CORPORA / "ros2bridge").glob("*.expected.json"))
    alone = [_expected(p) for p in every if not p.name.endswith(WITH)]
    paired = [_expected(p) for p in every if p.name.endswith(WITH)]
    releases = sorted({s["px4_release"] for s in alone}, key=_release_key)
    agree = sum(n for (v, _, ok), n in gate.items() if v == BRIDGE and ok)
    judged = sum(n for (v, _, ok), n in gate.items() if v == BRIDGE and ok is not None)
    rows = [
        replace(
            _counted(
                "`corpora/ros2bridge/`",
                f"real PX4 SITL {', '.join(releases)} over its ROS 2 bridge (uXRCE-DDS): the"
                " companion's bags (mcap, sqlite3) and PX4's ULog, px4_ros_com's"
                " offboard_control and px4-ros2-interface-lib's mode registration reproduced, an"
                " Ackermann rover on its rover setpoints, a standard VTOL through its transition"
                " to FW, the airplane's gate on the ground",
                alone,
            ),
            gate=f"{agree}/{judged}" if judged else "-",
        )
    ]
    if paired:
        rows.append(
            _counted(
                "`corpora/ros2bridge/` `--with`",
                "the same bags, each linted with its flight's ULog (`lint BAG --with ULOG`:"
                " what was sent and never received, OFB108)",
                paired,
            )
        )
    return rows


def _counted(recordings: str, what: str, specs: list[dict[str, Any]]) -> Row:
    clean = [s for s in specs if s["kind"] == "clean"]
    hazards = [s for s in specs if s["kind"] == "hazard"]
    return Row(
        recordings,
        what,
        len(clean),
        sum(map(_loud, clean)),
        len(hazards),
        sum(bool(_errors(h) & set(h["hazard"])) for h in hazards),
    )


BRIDGE = "ros2bridge"
"""The gate counter's key for the bridge flights (beside the SITL vehicles')."""


def bridge_agreement() -> Counter[tuple[str, str, bool | None]]:
    """(``BRIDGE``, kind, agree) over every ROS 2 bridge flight: the model run on the bag
    against PX4's ULog (``fuzzoff.sitl.ros2.verdict``)."""
    from fuzzoff.sitl.airframes import DEFAULT, airframe_for
    from fuzzoff.sitl.ros2.verdict import compare

    folder = CORPORA / "ros2bridge"
    runs: dict[str, Any] = json.loads((folder / "runs.json").read_text())
    counts: Counter[tuple[str, str, bool | None]] = Counter()
    for stem, run in sorted(runs.items()):
        release = run["release"].split("-")[0]
        # judged as the vehicle it flew (the standard VTOL as a VTOL), as over MAVLink
        vehicle = airframe_for(run.get("vehicle", DEFAULT)).fuzzoff_vehicle
        verdict = compare(folder / f"{stem}-mcap", release, folder / f"{stem}.ulg", vehicle=vehicle)
        for item in verdict.items:
            counts[(BRIDGE, _kind(item.what), item.agree)] += 1
    return counts


def tlog_row() -> Row:
    """PX4's MAVLink as it sends it (development dialect), from both ends of the link."""
    specs = [_expected(p) for p in sorted((CORPORA / "tlog").glob("px4_*.expected.json"))]
    clean = [s for s in specs if s["exit_status"] == 0 and not _errors(s)]
    hazards = [s for s in specs if s not in clean]
    return Row(
        "`corpora/tlog/px4_*`",
        "real PX4 1.16.2 and 1.17.0 tlogs, the companion's and the ground station's"
        " (a double ack, a loss)",
        len(clean),
        sum(map(_loud, clean)),
        len(hazards),
        sum(bool(_errors(h)) for h in hazards),
    )


def _release_key(release: str) -> tuple[tuple[int, ...], str]:
    """Oldest first; a pre-release after its number's others by name (alpha before beta); a
    build of main (``main-2026-08-13``) last."""
    base = release.split("-")[0]
    if not base.replace(".", "").isdigit():
        return (999,), release
    return tuple(int(p) for p in base.split(".")), release


def gate_agreement() -> Counter[tuple[str, str, bool | None]]:
    """(vehicle, kind, agree) over every recorded SITL exchange: the model run on the
    client's tlog against PX4's ULog, as ``tests/test_sitl.py`` judges each."""
    from fuzzoff.sitl.airframes import DEFAULT, airframe_for
    from fuzzoff.sitl.link import COMPANION_SYSID
    from fuzzoff.sitl.verdict import compare

    sitl = CORPORA / "sitl"
    runs: dict[str, Any] = json.loads((sitl / "runs.json").read_text())
    counts: Counter[tuple[str, str, bool | None]] = Counter()
    for stem, run in sorted(runs.items()):
        tlog, ulog = sitl / f"{stem}.tlog", sitl / f"{stem}.ulg"
        if not (tlog.exists() and ulog.exists()):
            continue
        release = run["release"].split("-")[0]
        flown = run.get("vehicle", DEFAULT)
        vehicle = airframe_for(flown).fuzzoff_vehicle
        verdict = compare(tlog, release, ulog, run.get("params") or {}, COMPANION_SYSID, vehicle)
        for item in verdict.items:
            counts[(flown, _kind(item.what), item.agree)] += 1
    return counts


def _kind(what: str) -> str:
    if what in ("loss time", "failsafe action", "automatic return"):
        return what
    if what in ("offboard loss", "recorded vs model"):
        return "offboard loss"
    return "switch, arm or disarm"


GATE_KINDS = {
    "switch, arm or disarm": "switch, arm or disarm accepted or rejected",
    "offboard loss": "stream loss predicted where PX4 lost the stream, and only there",
    "loss time": "loss time within PX4's 10 Hz check window (ULog flag; 110 ms)",
    "failsafe action": "failsafe action (POSCTL, Return, Land, disarm)",
    "automatic return": "automatic return to OFFBOARD after the stream resumes",
}


def render(rows: Iterable[Row], by_vehicle: Counter[tuple[str, str, bool | None]]) -> str:
    lines = [
        "| recordings | what | clean | warning or error on a clean one | hazards | hazard"
        " given as an error | gate model agrees with PX4 |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    rows = list(rows)
    for r in rows:
        lines.append(
            f"| {r.recordings} | {r.what} | {r.clean} | {r.loud_on_clean} | {r.hazards} |"
            f" {r.caught} | {r.gate} |"
        )
    total = Row(
        "all",
        "",
        sum(r.clean for r in rows),
        sum(r.loud_on_clean for r in rows),
        sum(r.hazards for r in rows),
        sum(r.caught for r in rows),
    )
    gate: Counter[tuple[str, bool | None]] = Counter()
    for (_, kind, agree), n in by_vehicle.items():
        gate[(kind, agree)] += n
    agreed = sum(n for (_, ok), n in gate.items() if ok)
    judged = sum(n for (_, ok), n in gate.items() if ok is not None)
    lines.append(
        f"| **all** | | **{total.clean}** | **{total.loud_on_clean}** | **{total.hazards}** |"
        f" **{total.caught}** | **{agreed}/{judged}** |"
    )
    lines += ["", "| the gate model against PX4 SITL | agree | differ | not judged |"]
    lines.append("| --- | --- | --- | --- |")
    for kind, label in GATE_KINDS.items():
        agree, differ, unjudged = (gate[(kind, v)] for v in (True, False, None))
        if kind == "offboard loss":  # each loss both saw is judged once, on its time
            agree = sum(gate[("loss time", v)] for v in (True, False, None))
        lines.append(f"| {label} | {agree} | {differ} | {unjudged} |")
    return "\n".join(lines) + "\n"


def table() -> str:
    gate = gate_agreement() + bridge_agreement()
    return render([examples_row(), *sitl_rows(gate), *ros2bridge_rows(gate), tlog_row()], gate)


if __name__ == "__main__":
    sys.stdout.write(table())
