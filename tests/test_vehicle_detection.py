"""The vehicle type a recording says, and what is assumed where it says only part of it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.helpers import run_cli

ROVER = Path(__file__).resolve().parents[1] / "corpora" / "rules_rover"


@pytest.mark.parametrize(
    ("name", "topic"),
    [
        ("good_position", "/fmu/in/rover_position_setpoint"),
        ("good_speed_attitude", "/fmu/in/rover_speed_setpoint"),
        ("good_speed_rate", "/fmu/in/rover_rate_setpoint"),
        ("good_throttle_steering", "/fmu/in/rover_throttle_setpoint"),
    ],
)
def test_rover_topics_make_a_rover_whose_kind_is_said_to_be_assumed(name: str, topic: str) -> None:
    # no --vehicle: the good rover recordings were linted as a multicopter and failed
    result = run_cli(["lint", str(ROVER / f"{name}.mcap"), "--format", "json"])
    assert result.returncode == 0, result.stdout
    (report,) = json.loads(result.stdout)["files"]
    assert report["profile"]["vehicle"] == "rover-differential"
    assert report["profile"]["vehicle_source"] == "recording"
    (assumed,) = [f for f in report["findings"] if f["code"] == "OFB003"]
    assert topic in assumed["message"] and "assumed rover-differential" in assumed["message"]
    assert all(f["severity"] == "info" for f in report["findings"])


def test_the_users_rover_kind_wins_and_nothing_is_assumed() -> None:
    result = run_cli(
        [
            "lint",
            str(ROVER / "good_position.mcap"),
            "--vehicle",
            "rover-mecanum",
            "--format",
            "json",
        ]
    )
    (report,) = json.loads(result.stdout)["files"]
    assert report["profile"]["vehicle"] == "rover-mecanum"
    assert "OFB003" not in [f["code"] for f in report["findings"]]
