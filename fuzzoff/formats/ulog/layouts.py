"""uORB message formats as PX4 logs them, per release era (formats.md 2.2, 8.1; seed 003).

Only the topics fuzzoff reads, and only the fields they need plus enough of the rest to look
like PX4's; a field list starts at the era named and holds until the next entry. Trailing
``_padding0`` fields are declared as PX4 declares them and, like PX4, never written in the data
(formats.md 8.3).
"""

from __future__ import annotations

from typing import get_args

from fuzzoff import releases
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.uorb import TOPICS
from fuzzoff.profiles import px4_profile_for

ERAS: tuple[str, ...] = get_args(releases.UlogEra)
"""``legacy`` = v1.5-v1.11 (ignore_* control mode), ``1.13`` = v1.12-v1.13, ``1.17`` = 1.17+;
a release names its era in ``fuzzoff/releases.py`` (``Release.ulog_era``)."""


def era_for(px4_version: str | None) -> str:
    """The format era of a release (``1.15.4``) or profile name; 1.15 when unknown."""
    if px4_version is None:
        return "1.15"
    return releases.get(px4_profile_for(px4_version)).ulog_era


# Nested type used by position_setpoint_triplet (legacy and 1.13).
POSITION_SETPOINT = [
    "uint64_t timestamp",
    "double lat",
    "double lon",
    "float x",
    "float y",
    "float z",
    "float vx",
    "float vy",
    "float vz",
    "float alt",
    "float yaw",
    "float yawspeed",
    "float a_x",
    "float a_y",
    "float a_z",
    "float acceptance_radius",
    "float cruising_speed",
    "bool valid",
    "uint8_t type",
    "bool position_valid",
    "bool velocity_valid",
    "bool alt_valid",
    "bool yaw_valid",
    "bool yawspeed_valid",
    "bool acceleration_valid",
    "bool acceleration_is_force",
    "uint8_t[7] _padding0",
]

FORMATS: dict[str, list[tuple[str, list[str]]]] = {
    "offboard_control_mode": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "bool ignore_thrust",
                "bool ignore_attitude",
                "bool ignore_bodyrate_x",
                "bool ignore_bodyrate_y",
                "bool ignore_bodyrate_z",
                "bool ignore_position",
                "bool ignore_velocity",
                "bool ignore_acceleration_force",
                "bool ignore_alt_hold",
                "uint8_t[7] _padding0",
            ],
        ),
    ],
    "vehicle_local_position": [
        # as logged by PX4 v1.6 (pyulog's sample.ulg)
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint64_t ref_timestamp",
                "double ref_lat",
                "double ref_lon",
                "uint64_t surface_bottom_timestamp",
                "float x",
                "float y",
                "float z",
                "float[2] delta_xy",
                "float delta_z",
                "float vx",
                "float vy",
                "float vz",
                "float[2] delta_vxy",
                "float delta_vz",
                "float yaw",
                "float ref_alt",
                "float dist_bottom",
                "float dist_bottom_rate",
                "float eph",
                "float epv",
                "bool xy_valid",
                "bool z_valid",
                "bool v_xy_valid",
                "bool v_z_valid",
                "uint8_t xy_reset_counter",
                "uint8_t z_reset_counter",
                "uint8_t vxy_reset_counter",
                "uint8_t vz_reset_counter",
                "bool xy_global",
                "bool z_global",
                "bool dist_bottom_valid",
                "uint8_t[5] _padding0",
            ],
        ),
    ],
    "trajectory_setpoint": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "float x",
                "float y",
                "float z",
                "float yaw",
                "float yawspeed",
                "float vx",
                "float vy",
                "float vz",
                "float[3] acceleration",
                "float[3] jerk",
                "float[3] thrust",
                "uint8_t[4] _padding0",
            ],
        ),
    ],
    "vehicle_attitude_setpoint": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "float roll_body",
                "float pitch_body",
                "float yaw_body",
                "float yaw_sp_move_rate",
                "float[4] q_d",
                "float[3] thrust_body",
                "bool roll_reset_integral",
                "bool pitch_reset_integral",
                "bool yaw_reset_integral",
                "bool fw_control_yaw",
                "uint8_t apply_flaps",
                "uint8_t[7] _padding0",
            ],
        ),
    ],
    "vehicle_rates_setpoint": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "float roll",
                "float pitch",
                "float yaw",
                "float[3] thrust_body",
            ],
        ),
    ],
    "vehicle_thrust_setpoint": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint64_t timestamp_sample",
                "float[3] xyz",
                "uint8_t[4] _padding0",
            ],
        )
    ],
    "vehicle_torque_setpoint": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint64_t timestamp_sample",
                "float[3] xyz",
                "uint8_t[4] _padding0",
            ],
        )
    ],
    "actuator_motors": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint64_t timestamp_sample",
                "float[8] control",
                "uint16_t reversible_flags",
                "uint8_t[6] _padding0",
            ],
        ),
    ],
    "actuator_servos": [
        ("legacy", ["uint64_t timestamp", "uint64_t timestamp_sample", "float[8] control"]),
    ],
    "position_setpoint_triplet": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "position_setpoint previous",
                "position_setpoint current",
                "position_setpoint next",
            ],
        ),
    ],
    "vehicle_status": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint8_t nav_state",
                "uint8_t arming_state",
                "uint8_t hil_state",
                "bool failsafe",
                "uint8_t system_type",
                "uint8_t system_id",
                "uint8_t component_id",
                "bool is_rotary_wing",
                "bool is_vtol",
                "bool vtol_fw_permanent_stab",
                "bool in_transition_mode",
                "bool data_link_lost",
                "uint8_t[4] _padding0",
            ],
        ),
    ],
    "commander_state": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint16_t main_state_changes",
                "uint8_t main_state",
                "uint8_t[5] _padding0",
            ],
        ),
    ],
    "vehicle_control_mode": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "bool flag_armed",
                "bool flag_multicopter_position_control_enabled",
                "bool flag_control_manual_enabled",
                "bool flag_control_auto_enabled",
                "bool flag_control_offboard_enabled",
                "bool flag_control_rates_enabled",
                "bool flag_control_attitude_enabled",
                "bool flag_control_acceleration_enabled",
                "bool flag_control_velocity_enabled",
                "bool flag_control_position_enabled",
                "bool flag_control_altitude_enabled",
                "bool flag_control_climb_rate_enabled",
                "bool flag_control_termination_enabled",
                "uint8_t[3] _padding0",
            ],
        ),
    ],
    "vehicle_status_flags": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "bool condition_home_position_valid",
                "bool condition_local_altitude_valid",
                "bool condition_local_position_valid",
                "bool condition_local_velocity_valid",
                "bool condition_global_position_valid",
                "bool condition_attitude_valid",
                "bool condition_angular_velocity_valid",
                "bool rc_signal_lost",
                "bool offboard_control_signal_lost",
                "uint8_t[7] _padding0",
            ],
        ),
    ],
    "vehicle_land_detected": [
        (
            "1.14",
            [
                "uint64_t timestamp",
                "bool freefall",
                "bool ground_contact",
                "bool maybe_landed",
                "bool landed",
                "bool in_ground_effect",
                "bool in_descend",
                "bool has_low_throttle",
                "bool vertical_movement",
                "bool horizontal_movement",
                "bool rotational_movement",
                "bool close_to_ground_or_skipped_check",
                "bool at_rest",
                "uint8_t[4] _padding0",
            ],
        ),
    ],
    "manual_control_setpoint": [
        (
            "1.14",
            [
                "uint64_t timestamp",
                "uint64_t timestamp_sample",
                "float roll",
                "float pitch",
                "float yaw",
                "float throttle",
                "float flaps",
                "float aux1",
                "float aux2",
                "float aux3",
                "float aux4",
                "float aux5",
                "float aux6",
                "uint16_t buttons",
                "bool valid",
                "uint8_t data_source",
                "bool sticks_moving",
                "uint8_t[3] _padding0",
            ],
        ),
    ],
    "vehicle_command": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "double param5",
                "double param6",
                "float param1",
                "float param2",
                "float param3",
                "float param4",
                "float param7",
                "uint32_t command",
                "uint8_t target_system",
                "uint8_t target_component",
                "uint8_t source_system",
                "uint8_t source_component",
                "uint8_t confirmation",
                "bool from_external",
                "uint8_t[2] _padding0",
            ],
        ),
    ],
    "vehicle_command_ack": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint32_t command",
                "int32_t result_param2",
                "uint8_t result",
                "uint8_t result_param1",
                "uint8_t target_system",
                "uint8_t target_component",
                "bool from_external",
                "uint8_t[3] _padding0",
            ],
        ),
    ],
    # Busy topics that are not about offboard (the benchmark's mixed log).
    "sensor_combined": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "float[3] gyro_rad",
                "uint32_t gyro_integral_dt",
                "int32_t accelerometer_timestamp_relative",
                "float[3] accelerometer_m_s2",
                "uint32_t accelerometer_integral_dt",
                "uint8_t accelerometer_clipping",
                "uint8_t[3] _padding0",
            ],
        )
    ],
    "vehicle_imu": [
        (
            "legacy",
            [
                "uint64_t timestamp",
                "uint64_t timestamp_sample",
                "uint32_t accel_device_id",
                "uint32_t gyro_device_id",
                "float[3] delta_angle",
                "float[3] delta_velocity",
                "uint16_t delta_angle_dt",
                "uint16_t delta_velocity_dt",
                "uint8_t delta_angle_clipping",
                "uint8_t delta_velocity_clipping",
                "uint8_t calibration_count",
                "uint8_t[1] _padding0",
            ],
        )
    ],
}

NESTED: dict[str, list[str]] = {"position_setpoint": POSITION_SETPOINT}


def fields_for(topic: str, era: str) -> list[str] | None:
    """The field list of ``topic`` in ``era``, or None when that era has no such topic: from
    the release's px4_msgs ``.msg`` file where it has one, else from ``FORMATS``."""
    message = TOPICS[topic].message if topic in TOPICS else None
    if message is not None and era in px4_msgs.folders():
        derived = px4_msgs.ulog_fields(era, message)
        if derived is not None:
            return list(derived)
    chosen: list[str] | None = None
    for first, fields in FORMATS.get(topic, ()):
        if ERAS.index(first) <= ERAS.index(era):
            chosen = fields
    return chosen


def earliest_fields(topic: str) -> list[str]:
    """The field list of ``topic`` in the first era that has it: what the writer declares for a
    topic written into a log of a release from before it existed."""
    for era in ERAS:
        fields = fields_for(topic, era)
        if fields is not None:
            return fields
    raise KeyError(topic)
