"""Normalised events -> a PX4 ULog, written by pyulog 1.3's own ``ULog.write_ulog``.

The ``ULog`` object is filled the way pyulog's reader fills it (formats, info, initial and
changed parameters, per-topic data, logged messages, dropouts), so the file is what pyulog
would write back for a PX4 log of that release. Field layouts per era are in
``ulog_formats``; like PX4, trailing padding is declared in the format and never written.

What a ULog cannot say: a parameter change or a dropout has no timestamp of its own; a reader
dates it at the last data message before it (write one at the same time to keep its time).
Events no uORB topic carries (MAVLink setpoints) are skipped.
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from pyulog import ULog

from fuzzoff import events as ev
from fuzzoff.formats.ulog.layouts import NESTED, earliest_fields, era_for, fields_for
from fuzzoff.formats.uorb import NAV_TO_MAIN_STATE

DEFAULT_START_US = 20_000_000
"""PX4's logger starts some seconds after boot; the header timestamp is that moment."""

Row = dict[str, Any]
ParamValue = int | float

FLOAT_PARAMS = frozenset({"COM_OF_LOSS_T", "COM_FAIL_ACT_T", "COM_RC_LOSS_T", "MPC_XY_VEL_MAX"})
"""Parameters PX4 declares as float; any other integral value is written as int32."""

VEHICLE_PARAMS: dict[str, tuple[int, int]] = {
    "mc": (0, 2),
    "fw": (1, 1),
    "vtol": (2, 22),
    "rover-ackermann": (5, 10),
    "rover-differential": (6, 10),
    "rover-mecanum": (13, 10),
}
"""Vehicle type -> (CA_AIRFRAME, MAV_TYPE)."""

STATUS_VEHICLE_TYPE = {"mc": 1, "fw": 2, "vtol": 1}

SUBSCRIBED = ("offboard_control_mode",)
"""Topics of PX4's default logger profile whose format a log holds even when nothing was
published: the logger writes the format of every subscribed topic at the start (PX4 logs
``offboard_control_mode`` for every offboard source, so its format without data says no
stream was sent; a log without the format was not logging it)."""

_RELEASE = re.compile(r"^v?(\d+)\.(\d+)(?:\.(\d+))?(?:-?(\w+))?")
_RELEASE_TYPE = {"alpha": 64, "beta": 128, "rc": 192}


def ver_sw_release(version: str) -> int:
    """PX4's ``ver_sw_release`` word ``0xAABBCCTT`` (TT 255 = release, <64 = development)."""
    match = _RELEASE.match(version.strip())
    if match is None:
        raise ValueError(f"not a PX4 release: {version!r}")
    major, minor, patch = (int(match.group(i) or 0) for i in (1, 2, 3))
    suffix = (match.group(4) or "").lower()
    kind = 255 if not suffix else _RELEASE_TYPE.get(re.sub(r"\d+$", "", suffix), 0)
    return (major << 24) | (minor << 16) | (patch << 8) | kind


def _vec(name: str, values: Iterable[float]) -> Row:
    return {f"{name}[{i}]": v for i, v in enumerate(values)}


def _nan(value: float | None) -> float:
    return math.nan if value is None else value


class _Topics:
    """Rows per topic, built from events by one small function per event type."""

    def __init__(self, era: str, start_us: int, vehicle_type: str | None) -> None:
        self.era = era
        self.start_us = start_us
        self.vehicle_type = vehicle_type
        self.rows: dict[str, list[Row]] = {}
        self.changed_params: list[tuple[int, str, ParamValue]] = []
        self.initial_params: dict[str, ParamValue] = {}
        self.logged: list[tuple[int, int, str]] = []
        self.dropouts: list[tuple[int, int]] = []
        self.handlers: dict[type[ev.Event], Callable[[Any, int], None]] = {
            ev.ControlMode: self._control_mode,
            ev.LegacyControlMode: self._legacy_control_mode,
            ev.TrajectorySetpoint: self._trajectory,
            ev.AttitudeSetpoint: self._attitude,
            ev.RatesSetpoint: self._rates,
            ev.ThrustSetpoint: self._xyz("vehicle_thrust_setpoint"),
            ev.TorqueSetpoint: self._xyz("vehicle_torque_setpoint"),
            ev.ActuatorMotors: self._motors,
            ev.ActuatorServos: self._servos,
            ev.RoverPositionSetpoint: self._rover_position,
            ev.RoverSpeedSetpoint: self._plain(
                "rover_speed_setpoint", ("speed_body_x", "speed_body_y")
            ),
            ev.RoverAttitudeSetpoint: self._plain("rover_attitude_setpoint", ("yaw_setpoint",)),
            ev.RoverRateSetpoint: self._plain("rover_rate_setpoint", ("yaw_rate_setpoint",)),
            ev.RoverThrottleSetpoint: self._plain(
                "rover_throttle_setpoint", ("throttle_body_x", "throttle_body_y")
            ),
            ev.RoverSteeringSetpoint: self._steering,
            ev.PositionSetpointTriplet: self._triplet,
            ev.VehicleStatus: self._status,
            ev.VehicleControlModeStatus: self._control_mode_status,
            ev.FailsafeFlags: self._failsafe_flags,
            ev.LandDetected: self._land_detected,
            ev.ManualControl: self._manual_control,
            ev.VehiclePosition: self._local_position,
            ev.Command: self._command,
            ev.CommandAck: self._ack,
            ev.Parameter: self._parameter,
            ev.StatusText: self._status_text,
            ev.Dropout: self._dropout,
        }

    def add(self, event: ev.Event) -> None:
        handler = self.handlers.get(type(event))
        if handler is not None:
            ts = self.start_us + round(event.t * 1e6)
            handler(event, ts)

    def _put(self, topic: str, ts: int, row: Row) -> None:
        row["timestamp"] = ts
        self.rows.setdefault(topic, []).append(row)

    @property
    def modern(self) -> bool:
        return self.era != "legacy"

    def _at_least(self, era: str) -> bool:
        from fuzzoff.formats.ulog.layouts import ERAS

        return ERAS.index(self.era) >= ERAS.index(era)

    # -- keep-alive and setpoints ----------------------------------------------------------

    def _control_mode(self, e: ev.ControlMode, ts: int) -> None:
        row: Row = {
            "position": e.position,
            "velocity": e.velocity,
            "acceleration": e.acceleration,
            "attitude": e.attitude,
            "body_rate": e.body_rate,
            "actuator": e.actuator or e.thrust_and_torque or e.direct_actuator,
            "thrust_and_torque": e.thrust_and_torque or e.actuator,
            "direct_actuator": e.direct_actuator,
        }
        self._put("offboard_control_mode", ts, row)

    def _legacy_control_mode(self, e: ev.LegacyControlMode, ts: int) -> None:
        row: Row = {
            "ignore_thrust": e.ignore_thrust,
            "ignore_attitude": e.ignore_attitude,
            "ignore_bodyrate": e.ignore_bodyrate,
            "ignore_bodyrate_x": e.ignore_bodyrate,
            "ignore_bodyrate_y": e.ignore_bodyrate,
            "ignore_bodyrate_z": e.ignore_bodyrate,
            "ignore_position": e.ignore_position,
            "ignore_velocity": e.ignore_velocity,
            "ignore_acceleration_force": e.ignore_acceleration_force,
            "ignore_alt_hold": e.ignore_alt_hold,
        }
        self._put("offboard_control_mode", ts, row)

    def _trajectory(self, e: ev.TrajectorySetpoint, ts: int) -> None:
        (x, y, z), (vx, vy, vz) = e.position, e.velocity
        row: Row = {"x": x, "y": y, "z": z, "vx": vx, "vy": vy, "vz": vz}
        row |= _vec("position", e.position) | _vec("velocity", e.velocity)
        row |= _vec("acceleration", e.acceleration) | _vec("jerk", e.jerk)
        row |= _vec("thrust", (math.nan,) * 3)
        row |= {"yaw": e.yaw, "yawspeed": e.yawspeed}
        self._put("trajectory_setpoint", ts, row)

    def _attitude(self, e: ev.AttitudeSetpoint, ts: int) -> None:
        row: Row = _vec("q_d", e.q_d) | _vec("thrust_body", e.thrust_body)
        row["yaw_sp_move_rate"] = e.yaw_sp_move_rate
        w, x, y, z = e.q_d
        if not any(math.isnan(v) for v in e.q_d):
            row["roll_body"] = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
            row["pitch_body"] = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
            row["yaw_body"] = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        self._put("vehicle_attitude_setpoint", ts, row)

    def _rates(self, e: ev.RatesSetpoint, ts: int) -> None:
        row: Row = {"roll": e.roll, "pitch": e.pitch, "yaw": e.yaw}
        self._put("vehicle_rates_setpoint", ts, row | _vec("thrust_body", e.thrust_body))

    def _xyz(self, topic: str) -> Callable[[Any, int], None]:
        def put(e: ev.ThrustSetpoint | ev.TorqueSetpoint, ts: int) -> None:
            self._put(topic, ts, {"timestamp_sample": ts} | _vec("xyz", e.xyz))

        return put

    def _motors(self, e: ev.ActuatorMotors, ts: int) -> None:
        row: Row = {"timestamp_sample": ts, "reversible_flags": e.reversible_flags}
        self._put("actuator_motors", ts, row | _vec("control", e.control))

    def _servos(self, e: ev.ActuatorServos, ts: int) -> None:
        self._put("actuator_servos", ts, {"timestamp_sample": ts} | _vec("control", e.control))

    def _rover_position(self, e: ev.RoverPositionSetpoint, ts: int) -> None:
        row: Row = _vec("position_ned", e.position_ned) | _vec("start_ned", e.start_ned)
        row |= {"cruising_speed": e.cruising_speed, "arrival_speed": e.arrival_speed}
        self._put("rover_position_setpoint", ts, row | {"yaw": e.yaw})

    def _plain(self, topic: str, names: tuple[str, ...]) -> Callable[[Any, int], None]:
        def put(e: ev.Event, ts: int) -> None:
            self._put(topic, ts, {name: getattr(e, name) for name in names})

        return put

    def _steering(self, e: ev.RoverSteeringSetpoint, ts: int) -> None:
        row: Row = {
            "normalized_steering_angle": e.normalized_steering_angle,
            "normalized_speed_diff": e.normalized_speed_diff,
            "normalized_steering_setpoint": e.normalized_steering_angle,
        }
        self._put("rover_steering_setpoint", ts, row)

    def _triplet(self, e: ev.PositionSetpointTriplet, ts: int) -> None:
        row: Row = {
            "previous.valid": e.previous_valid,
            "current.valid": e.current_valid,
            "next.valid": e.next_valid,
            "current.type": e.current_type,
            "current.position_valid": e.current_position_valid,
            "current.velocity_valid": e.current_velocity_valid,
            "current.yaw_valid": e.current_yaw_valid,
        }
        for part in ("previous", "current", "next"):
            row[f"{part}.timestamp"] = ts
        self._put("position_setpoint_triplet", ts, row)

    # -- vehicle state ---------------------------------------------------------------------

    def _status(self, e: ev.VehicleStatus, ts: int) -> None:
        vehicle_type = e.vehicle_type
        if vehicle_type is None:
            vehicle_type = STATUS_VEHICLE_TYPE.get(self.vehicle_type or "mc", 3)
        is_vtol = e.is_vtol if e.is_vtol is not None else self.vehicle_type == "vtol"
        nav_state = e.nav_state if e.nav_state is not None else 0
        row: Row = {
            "nav_state": nav_state,
            "nav_state_timestamp": ts,
            "arming_state": 2 if e.armed else 1,
            "failsafe": bool(e.failsafe),
            "vehicle_type": vehicle_type,
            "is_vtol": is_vtol,
            "is_rotary_wing": vehicle_type == 1,
            "system_type": {1: 2, 2: 1, 3: 10}.get(vehicle_type, 0),
            "system_id": 1,
            "component_id": 1,
        }
        if self._at_least("1.14"):
            intention = e.user_intention if e.user_intention is not None else nav_state
            row["nav_state_user_intention"] = intention
        elif e.user_intention is not None and e.user_intention in NAV_TO_MAIN_STATE:
            main = {"main_state": NAV_TO_MAIN_STATE[e.user_intention]}
            self._put("commander_state", ts, main)
        self._put("vehicle_status", ts, row)

    def _control_mode_status(self, e: ev.VehicleControlModeStatus, ts: int) -> None:
        row: Row = {f"flag_control_{name}_enabled": True for name in e.enabled}
        row["flag_control_offboard_enabled"] = e.offboard_enabled
        self._put("vehicle_control_mode", ts, row)

    def _failsafe_flags(self, e: ev.FailsafeFlags, ts: int) -> None:
        valid = {
            "local_position": e.local_position_valid,
            "local_velocity": e.local_velocity_valid,
            "local_altitude": e.local_altitude_valid,
            "global_position": e.global_position_valid,
            "attitude": e.attitude_valid,
            "angular_velocity": e.angular_velocity_valid,
            "home_position": e.home_position_valid,
        }
        lost_offboard = bool(e.offboard_control_signal_lost)
        lost_manual = bool(e.manual_control_signal_lost)
        if self._at_least("1.14"):
            row: Row = {f"{k}_invalid": v is False for k, v in valid.items()}
            row |= {
                "offboard_control_signal_lost": lost_offboard,
                "manual_control_signal_lost": lost_manual,
            }
            self._put("failsafe_flags", ts, row)
        else:
            row = {f"condition_{k}_valid": v is not False for k, v in valid.items()}
            row |= {"offboard_control_signal_lost": lost_offboard, "rc_signal_lost": lost_manual}
            self._put("vehicle_status_flags", ts, row)

    def _land_detected(self, e: ev.LandDetected, ts: int) -> None:
        landed = bool(e.landed)
        row: Row = {"landed": landed, "maybe_landed": landed, "ground_contact": landed}
        self._put("vehicle_land_detected", ts, row)

    def _manual_control(self, e: ev.ManualControl, ts: int) -> None:
        if not self._at_least("1.14"):
            return  # older layouts name the sticks otherwise: not written
        row: Row = {"roll": e.roll, "pitch": e.pitch, "yaw": e.yaw, "throttle": e.throttle}
        row |= {"valid": True, "sticks_moving": bool(e.sticks_moving), "timestamp_sample": ts}
        self._put("manual_control_setpoint", ts, row)

    def _local_position(self, e: ev.VehiclePosition, ts: int) -> None:
        xy = math.isfinite(e.x) and math.isfinite(e.y)
        row: Row = {"x": e.x if xy else 0.0, "y": e.y if xy else 0.0, "xy_valid": xy}
        row |= {"z": e.z if math.isfinite(e.z) else 0.0, "z_valid": math.isfinite(e.z)}
        self._put("vehicle_local_position", ts, row)

    def _command(self, e: ev.Command, ts: int) -> None:
        row: Row = {f"param{i + 1}": p for i, p in enumerate(e.params)}
        row |= {
            "command": e.command,
            "target_system": e.target_system,
            "target_component": e.target_component,
            "source_system": e.source_system or 0,
            "source_component": e.source_component or 0,
            "from_external": bool(e.from_external),
        }
        self._put("vehicle_command", ts, row)

    def _ack(self, e: ev.CommandAck, ts: int) -> None:
        row: Row = {
            "command": e.command,
            "result": e.result,
            "target_system": e.target_system,
            "target_component": e.target_component,
        }
        self._put("vehicle_command_ack", ts, row)

    # -- records that are not topics -------------------------------------------------------

    def _parameter(self, e: ev.Parameter, ts: int) -> None:
        value = _param_value(e.name, e.value)
        if e.t <= 0:
            self.initial_params[e.name] = value
        else:
            self.changed_params.append((ts, e.name, value))

    def _status_text(self, e: ev.StatusText, ts: int) -> None:
        self.logged.append((ts, ord("0") + max(0, min(7, e.severity)), e.text))

    def _dropout(self, e: ev.Dropout, ts: int) -> None:
        self.dropouts.append((ts, max(1, min(0xFFFF, round(e.duration_s * 1000)))))


def _param_value(name: str, value: float) -> ParamValue:
    if name not in FLOAT_PARAMS and float(value).is_integer():
        return int(value)
    return float(value)


def default_params(era: str, vehicle_type: str | None) -> dict[str, ParamValue]:
    """A few PX4 defaults the gate reads, and the parameters that name the airframe."""
    params: dict[str, ParamValue] = {"COM_OF_LOSS_T": 1.0 if era != "legacy" else 0.0}
    params["COM_OBL_RC_ACT"] = 0
    airframe, mav_type = VEHICLE_PARAMS.get(vehicle_type or "mc", (0, 2))
    params["MAV_TYPE"] = mav_type
    if era not in ("legacy", "1.13"):
        params["CA_AIRFRAME"] = airframe
    return params


def _format(name: str, fields: list[str]) -> Any:
    text = name + ":" + "".join(f"{field};" for field in fields)
    return ULog.MessageFormat(text.encode(), None)


def _dataset(
    topic: str, msg_id: int, columns: Mapping[str, Any], rows: int, formats: dict[str, Any]
) -> Any:
    """A ``ULog.Data`` built the way pyulog's reader builds one (same flattening and dtype).
    ``columns``: flattened field name (``position[0]``) -> values; None or absent = default
    (NaN for floats, 0 otherwise)."""
    record = struct.pack("<BH", 0, msg_id) + topic.encode()
    added = ULog._MessageAddLogged(record, None, formats)
    array = np.zeros(rows, dtype=added.dtype)
    for name in array.dtype.names or ():
        if name.startswith("_padding") or "._padding" in name:
            continue
        default: Any = math.nan if array.dtype[name].kind == "f" else 0
        values = columns.get(name)
        if values is None:
            array[name] = default
        elif isinstance(values, np.ndarray):
            array[name] = values
        else:
            array[name] = [default if v is None else v for v in values]
    added.buffer = bytearray(array.tobytes())
    return ULog.Data(added)


def _columns(rows: list[Row]) -> dict[str, list[Any]]:
    names = {name for row in rows for name in row}
    return {name: [row.get(name) for row in rows] for name in names}


def write_ulog(
    path: str | Path,
    events: Iterable[ev.Event],
    *,
    px4_version: str | None = "1.15.4",
    params: Mapping[str, ParamValue] | None = None,
    layout: str | None = None,
    vehicle_type: str | None = None,
    start_us: int = DEFAULT_START_US,
    subscribed: Iterable[str] = SUBSCRIBED,
    px4_branch: str | None = None,
) -> Path:
    """Write ``events`` as a ULog of ``px4_version`` (None: no ``ver_sw_release`` at all).

    ``layout`` forces the field layouts of an era (``legacy``, ``1.13``, ``1.14``, ``1.15``,
    ``1.16``, ``1.17``; default from ``px4_version``): ``legacy`` writes the ``ignore_*``
    control mode and the ``x, y, z`` trajectory, ``1.13`` the ``actuator`` flag and the
    ``x, y, z`` trajectory, ``1.14`` the ``position[3]`` trajectory, ``1.15``+ the
    ``thrust_and_torque``/``direct_actuator`` flags. ``params`` are the initial parameters
    (added to a few defaults); ``Parameter`` events at t > 0 become parameter changes.
    ``vehicle_type`` (or a ``VehicleInfo`` event) sets ``CA_AIRFRAME``/``MAV_TYPE``.
    ``subscribed``: topics whose format is written without data, as PX4's logger does for
    the topics of its profile (``()``: a logger that did not log the offboard stream).
    ``px4_branch``: the build's ``ver_sw_branch`` (``main``, ``release/1.18``).
    """
    era = layout or era_for(px4_version)
    stream = list(events)
    for event in stream:
        if isinstance(event, ev.VehicleInfo) and event.vehicle_type and vehicle_type is None:
            vehicle_type = event.vehicle_type
    topics = _Topics(era, start_us, vehicle_type)
    for event in stream:
        topics.add(event)
    ulog = _new_ulog(px4_version, start_us, px4_branch)
    initial = default_params(era, vehicle_type) | dict(params or {}) | topics.initial_params
    ulog._initial_parameters = dict(initial)
    ulog._changed_parameters = topics.changed_params
    columns = {topic: (_columns(rows), len(rows)) for topic, rows in topics.rows.items()}
    _add_topics(ulog, columns, era, subscribed)
    for ts, level, text in topics.logged:
        message = ULog.MessageLogging.__new__(ULog.MessageLogging)
        message.log_level, message.timestamp, message.message = level, ts, text
        ulog._logged_messages.append(message)
    for ts, duration_ms in topics.dropouts:
        dropout = ULog.MessageDropout.__new__(ULog.MessageDropout)
        dropout.duration, dropout.timestamp = duration_ms, ts
        ulog._dropouts.append(dropout)
    return _write(ulog, Path(path))


def write_ulog_columns(
    path: str | Path,
    topics: Mapping[str, Mapping[str, Any]],
    *,
    px4_version: str | None = "1.15.4",
    params: Mapping[str, ParamValue] | None = None,
    layout: str | None = None,
    start_us: int = DEFAULT_START_US,
) -> Path:
    """Write whole topics given as columns (uORB topic -> flattened field -> numpy array, with
    ``timestamp`` in microseconds): for logs too long to hold as events (the benchmarks)."""
    era = layout or era_for(px4_version)
    ulog = _new_ulog(px4_version, start_us)
    ulog._initial_parameters = default_params(era, None) | dict(params or {})
    sized = {topic: (cols, len(cols["timestamp"])) for topic, cols in topics.items()}
    _add_topics(ulog, sized, era)
    return _write(ulog, Path(path))


def _new_ulog(px4_version: str | None, start_us: int, branch: str | None = None) -> Any:
    ulog = ULog(None)
    ulog._file_version = 1
    ulog._start_timestamp = start_us
    info: dict[str, tuple[str, Any]] = {
        "sys_name": ("char[3]", "PX4"),
        "ver_hw": ("char[9]", "PX4_SITL"),
        "ver_sw": ("char[40]", "0" * 40),
    }
    if px4_version is not None:
        info["ver_sw_release"] = ("uint32_t", ver_sw_release(px4_version))
    if branch is not None:
        info["ver_sw_branch"] = (f"char[{len(branch)}]", branch)
    for key, (kind, value) in info.items():
        ulog._msg_info_dict[key] = value
        ulog._msg_info_dict_types[key] = kind
    return ulog


def _add_topics(
    ulog: Any,
    topics: Mapping[str, tuple[Mapping[str, Any], int]],
    era: str,
    subscribed: Iterable[str] = SUBSCRIBED,
) -> None:
    formats: dict[str, Any] = {name: _format(name, fields) for name, fields in NESTED.items()}
    for msg_id, topic in enumerate(sorted(topics)):
        fields = fields_for(topic, era) or earliest_fields(topic)
        formats[topic] = _format(topic, fields)
        columns, rows = topics[topic]
        ulog._data_list.append(_dataset(topic, msg_id, columns, rows, formats))
    for topic in subscribed:
        own = fields_for(topic, era)
        if topic not in formats and own is not None:
            formats[topic] = _format(topic, own)
    ulog._message_formats = formats


def _write(ulog: Any, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    ulog.write_ulog(str(path))
    return path
