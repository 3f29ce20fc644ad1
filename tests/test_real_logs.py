"""Real PX4 logs (corpora/real, see its README): the gate model agrees with what they recorded."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.helpers import CORPORA, run_cli

REAL = sorted((CORPORA / "real").glob("*.ulg"))


@pytest.mark.parametrize("log", REAL, ids=[p.name for p in REAL])
def test_gate_model_agrees_with_the_recorded_mode_history(log: Path) -> None:
    result = run_cli(["gate", str(log), "--format", "json"])
    assert result.returncode == 0, result.stdout[-2000:]
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is True
    assert report["vehicles"], "the log yields no vehicle"
    for vehicle in report["vehicles"]:
        assert vehicle["disagreements"] == []
        assert vehicle["timeline"], "no recorded mode to compare with"


def test_there_are_real_logs_to_check() -> None:
    assert len(REAL) >= 4


REAL_TLOGS = sorted((CORPORA / "tlog").glob("px4_*_*_*.*.tlog"))


@pytest.mark.parametrize("log", REAL_TLOGS, ids=[p.name for p in REAL_TLOGS])
def test_real_px4_tlogs_read_completely_and_the_gate_agrees(log: Path) -> None:
    # PX4 sends development-dialect ids pymavlink 2.4.50 does not know: ordinary traffic
    result = run_cli(["lint", str(log), "--format", "json"])
    assert result.returncode in (0, 1), result.stderr
    (report,) = json.loads(result.stdout)["files"]
    assert report["complete"] is True
    assert "OFB001" not in [f["code"] for f in report["findings"]]
    assert {"UNKNOWN_8", "UNKNOWN_410", "UNKNOWN_411"} <= set(report["stats"]["unknown"])
    assert report["stats"]["messages"]["CURRENT_MODE"] > 0
    gate = run_cli(["gate", str(log), "--format", "json"])
    (timeline,) = json.loads(gate.stdout)["files"]
    for vehicle in timeline["vehicles"]:
        assert vehicle["disagreements"] == []


def test_there_are_real_px4_tlogs_of_both_links() -> None:
    names = [p.name for p in REAL_TLOGS]
    assert any(".onboard." in n for n in names) and any(".gcs." in n for n in names)
