"""What PX4 publishes on /fmu/out beside its status: its verdict on the signals and estimates
(``failsafe_flags``), where it is (``vehicle_local_position``), and which release it is, as far
as the recording's message definitions and topic names tell."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.engine import Timeline, lint_file
from fuzzoff.events import (
    ControlMode,
    Event,
    FailsafeFlags,
    TrajectorySetpoint,
    VehiclePosition,
    VehicleStatus,
)
from fuzzoff.formats import open_source
from fuzzoff.formats.mcap.writer import write_mcap
from tests.helpers import CORPORA, run_cli

EXAMPLES = CORPORA / "examples"


def lint(path: Path, *args: str) -> dict[str, Any]:
    result = run_cli(["lint", str(path), "--format", "json", *args])
    assert result.returncode in (0, 1), result.stderr
    (report,) = json.loads(result.stdout)["files"]
    return dict(report)


@pytest.mark.parametrize(
    ("name", "release"),
    [
        ("px4_ros_com_offboard_control.mcap", "1.16"),
        ("px4_ros_com_offboard_control_py.mcap", "1.15"),
        ("px4_ros_com_ten_minute_hold.mcap", "1.17"),
        ("interface_lib_goto.mcap", "1.16"),
        ("rover_speed_attitude.mcap", "1.17"),
    ],
)
def test_the_examples_release_is_detected_from_what_px4_published(name: str, release: str) -> None:
    # the /fmu/out definitions differ per release (FailsafeFlags in every one)
    report = lint(EXAMPLES / name)
    assert report["profile"]["px4"] == release and report["profile"]["px4_detected"] is True


def test_failsafe_flags_on_fmu_out_are_px4s_own_verdict() -> None:
    # PX4 1.17 SITL without RC: the recorded manual_control_signal_lost says no manual control,
    # so a loss would run NAV_RCL_ACT (Return), as PX4 did; OFB305 is checkable
    report = lint(EXAMPLES / "px4_ros_com_ten_minute_hold.mcap")
    findings = report["findings"]
    assert not [f for f in findings if f["code"] == "OFB002" and "OFB305" in f["message"]]
    (summary,) = [f for f in findings if f["code"] == "OFB701"]
    assert "no manual control (recorded)" in summary["message"]
    assert "AUTO_RTL" in summary["message"]


def _stream(extra: list[Event]) -> list[Event]:
    events: list[Event] = [VehicleStatus(t=0.0, nav_state=14, armed=True, vehicle_type=1)]
    events += [ControlMode(t=0.1 * k, position=True) for k in range(1, 20)]
    events += [TrajectorySetpoint(t=0.1 * k + 0.01, position=(0, 0, -2.0)) for k in range(1, 20)]
    return sorted([*events, *extra], key=lambda e: e.t)


def test_topic_names_and_definitions_narrow_the_release_and_say_so(tmp_path: Path) -> None:
    # /fmu/out/vehicle_status_v1 and 1.16's VehicleStatus: 1.16 or 1.17 (the same layout)
    path = write_mcap(tmp_path / "v1.mcap", _stream([]), release="1.16")
    report = lint(path)
    assert report["profile"]["px4"] == "1.17" and report["profile"]["px4_detected"] is False
    (assumed,) = [f for f in report["findings"] if f["code"] == "OFB003"]
    assert "fit 1.16 or 1.17 (assumed 1.17; set --px4)" in assumed["message"]
    # 1.16's FailsafeFlags has a layout of its own: the release is known
    flags = [FailsafeFlags(t=0.05, offboard_control_signal_lost=False)]
    path = write_mcap(tmp_path / "flags.mcap", _stream(flags), release="1.16")
    assert lint(path)["profile"]["px4"] == "1.16"


def test_the_vehicle_position_is_read_once_a_second_and_invalid_heights_are_nan(
    tmp_path: Path,
) -> None:
    positions: list[Event] = [
        VehiclePosition(t=0.1 * k + 0.05, x=1.0, y=2.0, z=-0.1 * k) for k in range(20)
    ]
    positions.append(VehiclePosition(t=2.05, x=1.0, y=2.0, z=math.nan))  # z_valid false
    path = write_mcap(tmp_path / "pos.mcap", _stream(positions), release="1.16")
    with open_source(path) as source:
        source.probe()
        read = [e for e in source.events() if isinstance(e, VehiclePosition)]
    assert [(e.t, e.z) for e in read[:2]] == [
        (pytest.approx(0.05), pytest.approx(0.0)),
        (pytest.approx(1.05), pytest.approx(-1.0)),
    ]
    assert math.isnan(read[-1].z) and read[-1].where.topic == "/fmu/out/vehicle_local_position"
    # The plots get every position, beside the events: the lint judges the same thinned ones.
    timelines: dict[str, Timeline] = {}
    plotted = lint_file(path, timelines=timelines, plot_data=True)
    assert plotted.stats == lint_file(path).stats
    assert plotted.stats["kinds"]["vehicle_position"] == len(read)
    assert len(timelines[""].positions) == 21  # every one, 0.1 s apart
