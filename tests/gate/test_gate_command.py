"""``fuzzoff gate PATH``: the model's timeline beside the recorded mode (tlog written with the
real pymavlink writer)."""

from __future__ import annotations

import json
from pathlib import Path

from fuzzoff.events import Event, SetPositionTargetLocal, VehicleInfo, VehicleStatus
from fuzzoff.formats.tlog.writer import write_tlog
from tests.helpers import CORPORA, run_cli

OFFBOARD, POSCTL = 14, 2
SENT = {
    "vehicle": "1",
    "source_system": 1,
    "source_component": 191,
    "target_system": 1,
    "target_component": 1,
}


def _flight(path: Path, recorded_after_loss: int) -> Path:
    """Armed in OFFBOARD, setpoints at 20 Hz until 3.0 s, resumed at 6.0 s; 1 Hz HEARTBEAT
    showing ``recorded_after_loss`` from 5 s."""
    events: list[Event] = [
        VehicleInfo(t=0.0, vehicle="1", px4_version="1.15.4"),
        VehicleInfo(t=0.0, vehicle="1", mav_type=2, vehicle_type="mc"),
    ]
    for k in range(160):
        t = round(k * 0.05, 3)
        if 3.0 < t < 6.0:
            continue
        events.append(
            SetPositionTargetLocal(t=t, type_mask=0x09F8, position=(0.0, 0.0, -2.0), **SENT)  # type: ignore[arg-type]
        )
    for s in range(9):
        nav = recorded_after_loss if s == 5 else OFFBOARD
        events.append(VehicleStatus(t=float(s) + 0.01, vehicle="1", nav_state=nav, armed=True))
    events.sort(key=lambda e: e.t)
    return write_tlog(path, events)


def test_gate_json_timeline_agrees_with_recording(tmp_path: Path) -> None:
    path = _flight(tmp_path / "lost.tlog", POSCTL)
    result = run_cli(["gate", str(path), "--format", "json"])
    assert result.returncode == 0, result.stderr
    (file,) = json.loads(result.stdout)["files"]
    (vehicle,) = file["vehicles"]
    rows = vehicle["timeline"]
    failsafe = [r for r in rows if r["what"] == "failsafe"]
    assert [(r["action"], r["see"]) for r in failsafe] == [("POSCTL", "docs/gate.md#loss")]
    assert 4.0 <= failsafe[0]["time_s"] <= 4.12
    assert [r["what"] for r in rows if r["what"] == "offboard_resumed"] == ["offboard_resumed"]
    assert any(r["source"] == "recorded" and r["mode"] == "POSCTL" for r in rows)
    assert vehicle["disagreements"] == []


def test_gate_terminal_states_the_difference(tmp_path: Path) -> None:
    path = _flight(tmp_path / "stays.tlog", OFFBOARD)
    result = run_cli(["gate", str(path)])
    assert result.returncode == 1
    assert "recorded: OFFBOARD at 5.01 s; model: POSCTL" in result.stdout
    assert "gate.md#loss" in result.stdout and "failsafe" in result.stdout


def test_gate_param_override(tmp_path: Path) -> None:
    path = _flight(tmp_path / "long.tlog", OFFBOARD)
    result = run_cli(["gate", str(path), "--param", "COM_OF_LOSS_T=5", "--format", "json"])
    assert result.returncode == 0, result.stdout
    rows = json.loads(result.stdout)["files"][0]["vehicles"][0]["timeline"]
    assert not [r for r in rows if r["what"] == "failsafe"]


def test_gate_unreadable_file(tmp_path: Path) -> None:
    path = tmp_path / "junk.tlog"
    path.write_bytes(b"\x00garbage" * 10)
    result = run_cli(["gate", str(path)])
    assert result.returncode == 2
    assert "junk.tlog" in result.stderr
    assert "Traceback" not in result.stderr


def test_gate_missing_file(tmp_path: Path) -> None:
    result = run_cli(["gate", str(tmp_path / "nope.tlog")])
    assert result.returncode == 2


def test_gate_on_ulog_corpus() -> None:
    """The gate corpus ULogs: agreement exits 0, the planted difference exits 1."""
    agrees = run_cli(["gate", str(CORPORA / "gate" / "loss_and_resume_agrees.ulg")])
    assert agrees.returncode == 0, agrees.stdout
    assert "agrees with the model" in agrees.stdout
    differs = run_cli(["gate", str(CORPORA / "gate" / "recorded_stays_offboard.ulg")])
    assert differs.returncode == 1
    assert "recorded: OFFBOARD at 6.50 s; model: POSCTL" in differs.stdout
