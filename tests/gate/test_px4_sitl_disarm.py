"""The gate model against what real PX4 did (corpora/gate/px4_*_disarm_in_flight.*, written by
PX4 1.15.4 and 1.18.0-alpha1 SITL and the pymavlink client of corpora/gate/record_px4.py).

Each flight: a disarm request in flight (refused, ack 1), an arm request while armed (ack 0),
four stops of the stream (PX4's loss and failsafe, and its return to OFFBOARD), AUTO_LAND and a
disarm request just above the ground (refused: the land detector does not say landed yet).
Before issue 18's fixes the model accepted both disarms (OFB202 'arm acked
TEMPORARILY_REJECTED') and placed every loss on its own 10 Hz grid.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import run_cli

GATE = Path(__file__).resolve().parents[2] / "corpora" / "gate"
ULOGS = sorted(GATE.glob("px4_*_disarm_in_flight.ulg"))
TLOGS = sorted(GATE.glob("px4_*_disarm_in_flight.onboard.tlog"))


def _timeline(path: Path) -> list[dict[str, Any]]:
    result = run_cli(["gate", str(path), "--format", "json", "--no-controllers"])
    assert result.returncode == 0, result.stdout  # the recorded history agrees with the model
    (vehicle,) = json.loads(result.stdout)["files"][0]["vehicles"]
    rows: list[dict[str, Any]] = vehicle["timeline"]
    return rows


def test_the_recordings_are_there() -> None:
    assert len(ULOGS) == 2 and len(TLOGS) == 2


@pytest.mark.parametrize("path", [*ULOGS, *TLOGS], ids=lambda p: p.name)
def test_both_disarm_requests_are_refused_as_px4_refused_them(path: Path) -> None:
    rows = _timeline(path)
    refused = [r for r in rows if r["what"] == "disarm_rejected"]
    assert len(refused) == 2
    assert all(
        "Disarming denied: not landed (land detector: not landed" in r["reason"] for r in refused
    )
    assert not [r for r in rows if r["what"] == "disarmed"]
    assert any("already armed" in r["message"] for r in rows)


def _recorded_after(rows: list[dict[str, Any]], t: float) -> dict[str, Any]:
    return next(r for r in rows if r["source"] == "recorded" and r["time_s"] >= t - 1e-9)


@pytest.mark.parametrize("path", ULOGS, ids=lambda p: p.name)
def test_ulog_losses_are_dated_by_pxs_flag(path: Path) -> None:
    """PX4's failsafe_flags dates each loss; its failsafe shows in vehicle_status one
    Commander iteration later (within 20 ms)."""
    rows = _timeline(path)
    failsafes = [r for r in rows if r["what"] == "failsafe"]
    assert len(failsafes) == 4
    for row in failsafes:
        assert row["seen_in"] == "PX4's failsafe_flags"
        recorded = _recorded_after(rows, row["time_s"] - 0.02)
        assert recorded["mode"] == row["mode"]
        assert abs(recorded["time_s"] - row["time_s"]) <= 0.02


@pytest.mark.parametrize("path", TLOGS, ids=lambda p: p.name)
def test_tlog_losses_are_a_check_window_the_heartbeat_agrees_with(path: Path) -> None:
    """The onboard tlog has no phase of PX4's check: each loss is a 0.1 s window, and every
    change to the failsafe that PX4's 1 Hz HEARTBEAT shows comes after a window's start and
    at most a second after its end (a failsafe shorter than a second may fall between two)."""
    rows = _timeline(path)
    losses = [r for r in rows if r["what"] == "signal_lost" and r["time_s"] < 36.0]
    assert len(losses) == 4
    for row in losses:
        assert row["time_s"] - row["earliest_s"] == pytest.approx(0.1)
    windows = [(r["earliest_s"], r["time_s"]) for r in rows if r["what"] == "failsafe"]
    action = next(r["mode"] for r in rows if r["what"] == "failsafe")
    shown = [r["time_s"] for r in rows if r["source"] == "recorded" and r["mode"] == action]
    assert shown
    for t in shown:
        assert any(start <= t <= end + 1.02 for start, end in windows), t
