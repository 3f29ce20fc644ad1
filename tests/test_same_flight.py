"""One real PX4 flight, three recordings (``corpora/tlog/px4_1_16_2_clean.*``: the onboard
link's tlog, the ground station's tlog and PX4's own ULog): where two of them hold the same
data, fuzzoff must say the same thing from each."""

from __future__ import annotations

import json
from typing import Any

import pytest

from tests.helpers import CORPORA, run_cli

FLIGHT = CORPORA / "tlog" / "px4_1_16_2_clean"


def findings(suffix: str) -> list[dict[str, Any]]:
    result = run_cli(["lint", f"{FLIGHT}{suffix}", "--format", "json"])
    assert result.returncode == 0, result.stdout[-2000:]
    (report,) = json.loads(result.stdout)["files"]
    return list(report["findings"])


def test_the_controller_changes_agree_between_the_tlog_and_the_ulog() -> None:
    # the client flies 2 s of velocity setpoints between position ones: over MAVLink PX4's
    # receiver sets offboard_control_mode from each type mask, which the ULog logs
    tlog = [f for f in findings(".onboard.tlog") if f["code"] == "OFB304"]
    ulog = [f for f in findings(".ulg") if f["code"] == "OFB304"]
    changes = ["'position' to 'velocity'", "'velocity' to 'position'"]
    for found in (tlog, ulog):
        assert [c in f["message"] for f, c in zip(found, changes, strict=True)] == [True, True]
    # each in its own clock: the two changes are as far apart (the logger samples at 10 Hz)
    apart = [found[1]["time_s"] - found[0]["time_s"] for found in (tlog, ulog)]
    assert apart[0] == pytest.approx(apart[1], abs=0.11)


def test_the_three_recordings_lint_clean_and_the_gate_agrees_with_each() -> None:
    for suffix in (".onboard.tlog", ".gcs.tlog", ".ulg"):
        assert not [f for f in findings(suffix) if f["severity"] in ("warning", "error")]
        gate = run_cli(["gate", f"{FLIGHT}{suffix}", "--format", "json"])
        (report,) = json.loads(gate.stdout)["files"]
        assert all(vehicle["disagreements"] == [] for vehicle in report["vehicles"])
