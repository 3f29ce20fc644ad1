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
