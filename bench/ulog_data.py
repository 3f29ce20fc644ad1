"""Synthetic PX4 ULogs for the benchmark, written by pyulog through ``write_ulog_columns``.

``generate(path, messages)``: an offboard flight as a high-rate logger profile records it
(``offboard_control_mode`` and ``trajectory_setpoint`` at 50 Hz each, ``vehicle_status``,
``vehicle_control_mode`` and ``failsafe_flags`` now and then): nearly every message becomes an
event, the worst case for fuzzoff. ``mixed=True``: a log as PX4's default logger profile writes
it, ``sensor_combined`` and ``vehicle_imu`` making up over 98 % of the messages, the offboard
topics at 10 Hz and 5 Hz.
Deterministic; an existing file of the right name is reused.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from fuzzoff.formats.ulog.writer import DEFAULT_START_US, write_ulog_columns

Columns = dict[str, Any]


def _times(count: int, period_s: float, phase_s: float) -> Any:
    return DEFAULT_START_US + np.round((phase_s + np.arange(count) * period_s) * 1e6).astype(
        np.uint64
    )


def _vec(name: str, values: Any) -> Columns:
    return {f"{name}[{i}]": values[:, i] for i in range(values.shape[1])}


def _ocm(count: int, period: float) -> Columns:
    return {"timestamp": _times(count, period, 0.0), "position": np.ones(count, np.int8)}


def _trajectory(count: int, period: float) -> Columns:
    k = np.arange(count, dtype=np.float32)
    position = np.stack([np.sin(k / 500), np.cos(k / 500), np.full(count, -5.0)], axis=1)
    nan = np.full((count, 3), np.nan, np.float32)
    return {
        "timestamp": _times(count, period, 0.001),
        **_vec("position", position.astype(np.float32)),
        **_vec("velocity", nan),
        **_vec("acceleration", nan),
        **_vec("jerk", nan),
        "yaw": np.zeros(count, np.float32),
        "yawspeed": np.full(count, np.nan, np.float32),
    }


def _status(count: int, period: float) -> Columns:
    return {
        "timestamp": _times(count, period, 0.002),
        "nav_state": np.full(count, 14, np.uint8),
        "nav_state_user_intention": np.full(count, 14, np.uint8),
        "arming_state": np.full(count, 2, np.uint8),
        "vehicle_type": np.ones(count, np.uint8),
    }


def _control_mode(count: int, period: float) -> Columns:
    ones = np.ones(count, np.int8)
    return {
        "timestamp": _times(count, period, 0.003),
        "flag_armed": ones,
        "flag_control_offboard_enabled": ones,
        "flag_control_position_enabled": ones,
        "flag_control_velocity_enabled": ones,
    }


def _flags(count: int, period: float) -> Columns:
    return {"timestamp": _times(count, period, 0.004)}


def _sensor(name: str, count: int, period: float, phase: float) -> Columns:
    rng = np.random.default_rng(7)
    values = rng.normal(size=(count, 3)).astype(np.float32)
    if name == "sensor_combined":
        return {
            "timestamp": _times(count, period, phase),
            **_vec("gyro_rad", values),
            **_vec("accelerometer_m_s2", values * 9.81),
        }
    return {
        "timestamp": _times(count, period, phase),
        "timestamp_sample": _times(count, period, phase),
        **_vec("delta_angle", values * 0.004),
        **_vec("delta_velocity", values * 0.04),
    }


def generate(path: Path, messages: int, *, mixed: bool = False) -> Path:
    """Write (once) a ULog of about ``messages`` messages; returns its path."""
    if path.exists():
        return path
    topics: dict[str, Columns] = {}
    if mixed:
        # PX4's default logger profile: sensors at their own rate, offboard_control_mode at
        # 10 Hz and trajectory_setpoint at 5 Hz (formats.md 8.1): offboard is ~1.5 % of it.
        duration = messages / 966.0
        rates = {"sensor_combined": 500.0, "vehicle_imu": 450.0}
        for phase, (name, rate) in enumerate(rates.items()):
            topics[name] = _sensor(name, round(duration * rate), 1 / rate, 0.0002 * phase)
        ocm_rate, trajectory_rate = 10.0, 5.0
    else:  # a high-rate logger profile: 50 Hz each, every message an event
        duration = messages / 102.0
        ocm_rate = trajectory_rate = 50.0
    topics["offboard_control_mode"] = _ocm(round(duration * ocm_rate), 1 / ocm_rate)
    count = round(duration * trajectory_rate)
    topics["trajectory_setpoint"] = _trajectory(count, 1 / trajectory_rate)
    slow = round(duration)
    topics["vehicle_status"] = _status(slow, 1.0)
    topics["vehicle_control_mode"] = _control_mode(slow // 10 + 1, 10.0)
    topics["failsafe_flags"] = _flags(slow // 10 + 1, 10.0)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_suffix(".partial")
    write_ulog_columns(partial, topics, px4_version="1.15.4")
    partial.rename(path)
    return path
