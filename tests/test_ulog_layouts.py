"""The ULogs fuzzoff writes declare the offboard topics exactly as PX4 SITL logs them.

The layouts come from the bundled px4_msgs ``.msg`` files (one schema for ROS 2 and ULog); the
reference is the format records of the ULogs real PX4 SITL wrote for ``corpora/sitl``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from pyulog import ULog

from fuzzoff.events import ControlMode, VehicleStatus
from fuzzoff.formats.ulog.writer import write_ulog

SITL = Path(__file__).resolve().parent.parent / "corpora" / "sitl"

TOPICS = (
    "offboard_control_mode",
    "trajectory_setpoint",
    "vehicle_attitude_setpoint",
    "vehicle_rates_setpoint",
    "vehicle_status",
    "vehicle_control_mode",
    "failsafe_flags",
    "vehicle_command",
    "vehicle_command_ack",
    "vehicle_local_position",
)


def _declared(path: Path) -> dict[str, list[tuple[str, int, str]]]:
    formats = ULog(str(path), message_name_filter_list=[]).message_formats
    return {name: list(fmt.fields) for name, fmt in formats.items()}


@pytest.mark.parametrize("release", ["1.14.4", "1.15.4", "1.16.2", "1.17.0"])
def test_written_layouts_are_those_px4_logs(tmp_path: Path, release: str) -> None:
    real = _declared(SITL / f"clean_offboard-{release}.ulg")
    events = [VehicleStatus(t=0.0, nav_state=14, armed=True), ControlMode(t=0.1, position=True)]
    path = write_ulog(tmp_path / "w.ulg", events, px4_version=release, subscribed=TOPICS)
    written = _declared(path)
    for topic in TOPICS:
        assert topic in real, topic
        assert written.get(topic) == real[topic], topic
