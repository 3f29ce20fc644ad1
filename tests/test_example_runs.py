"""The raw PX4 runs behind the official examples (``corpora/examples/runs``): PX4's own ULog, cut
to the vehicle-side topics, and the real MAVLink exchange as a tlog. A user lints such files as
they come, without options, so:

* every clean run lints with exit 0 at the default fail level, from its ULog and its tlog;
* a ULog without ``offboard_control_mode`` holds no stream: the stream rules are not checkable
  there (one OFB002), and the gate model takes PX4's recorded ``offboard_control_signal_lost``
  as the offboard signal, so it agrees with PX4 and a real loss is still judged;
* the gate model agrees with the recorded mode history of every run.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import CORPORA, run_cli

RUNS = CORPORA / "examples" / "runs"
CLEAN = sorted(
    p for p in RUNS.iterdir() if p.suffix in (".ulg", ".tlog") and not p.name.startswith("hazard")
)
ALL = sorted(p for p in RUNS.iterdir() if p.suffix in (".ulg", ".tlog"))


def lint(path: Path, *args: str) -> tuple[int, list[dict[str, Any]]]:
    result = run_cli(["lint", str(path), "--format", "json", *args])
    assert result.returncode in (0, 1), result.stderr
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"], path.name
    return result.returncode, report["findings"]


def loud(findings: list[dict[str, Any]]) -> list[str]:
    return [
        f"{f['code']} {f['severity']} at {f['time_s']}: {f['message']}"
        for f in findings
        if f["severity"] in ("error", "warning")
    ]


def test_there_are_clean_runs_of_both_formats() -> None:
    assert {p.suffix for p in CLEAN} == {".ulg", ".tlog"} and len(CLEAN) >= 14


@pytest.mark.parametrize("run", CLEAN, ids=[p.name for p in CLEAN])
def test_clean_run_lints_clean(run: Path) -> None:
    code, findings = lint(run)
    assert loud(findings) == [] and code == 0


@pytest.mark.parametrize("run", ALL, ids=[p.name for p in ALL])
def test_gate_model_agrees_with_the_run(run: Path) -> None:
    result = run_cli(["gate", str(run), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    for vehicle in report["vehicles"]:
        assert vehicle["disagreements"] == []


def test_a_ulog_without_offboard_control_mode_says_the_stream_rules_cannot_be_checked() -> None:
    # the run's ULog keeps vehicle_status, commands, acks, positions and failsafe_flags only
    _code, findings = lint(RUNS / "px4_ros_com_offboard_control.ulg")
    codes = [f["code"] for f in findings]
    (note,) = [f for f in findings if f["code"] == "OFB002"]
    assert "offboard_control_mode" in note["message"] and "OFB103" in note["message"]
    assert "offboard_control_signal_lost" in note["message"]
    assert not {"OFB101", "OFB102", "OFB103", "OFB202"} & set(codes)


def _gate(run: Path) -> list[dict[str, Any]]:
    result = run_cli(["gate", str(run), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    (vehicle,) = report["vehicles"]
    return list(vehicle["timeline"])


def test_without_the_stream_px4s_own_flag_is_the_signal_and_a_real_loss_is_judged() -> None:
    # the timer stalls 1.5 s at 5 m: PX4 flags the loss, goes to Position and back
    run = RUNS / "hazard_stall_mid_air.ulg"
    timeline = _gate(run)
    lost = [e for e in timeline if e.get("what") == "signal_lost"]
    assert lost and "offboard_control_signal_lost" in lost[-1]["message"]
    _code, findings = lint(run)
    (loss,) = [f for f in findings if f["code"] == "OFB702" and f["severity"] == "error"]
    assert loss["time_s"] == pytest.approx(lost[-1]["time_s"], abs=1e-6)
    assert "OFB103" not in [f["code"] for f in findings]
