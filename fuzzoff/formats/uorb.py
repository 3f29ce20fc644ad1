"""uORB values that ULogs and px4_msgs recordings share, for readers and writers alike.

A ULog logs uORB topics as PX4 publishes them; a ROS 2 recording carries the same messages as
px4_msgs. What both formats' readers and writers must agree on lives here, so a writer never
reaches into a reader for it.
"""

from __future__ import annotations

ARMING_STATE_DISARMED = 1
"""STANDBY in 1.13/1.14, DISARMED from 1.15: 1 in both numberings."""
ARMING_STATE_ARMED = 2
"""``arming_state`` value for armed in every release (1.13/1.14 and 1.15+ numberings agree)."""

ESTIMATES = (
    "local_position",
    "local_velocity",
    "local_altitude",
    "global_position",
    "attitude",
    "angular_velocity",
    "home_position",
)
"""The estimates ``failsafe_flags`` (``<estimate>_invalid``, v1.14+) and ``vehicle_status_flags``
(``<estimate>_valid``, older) report on."""

MAIN_STATE_TO_NAV: dict[int, int] = {
    0: 0,
    1: 1,
    2: 2,
    3: 3,
    4: 4,
    5: 5,
    6: 10,
    7: 14,
    8: 15,
    9: 16,
    10: 17,
    11: 18,
    12: 19,
    13: 20,
    14: 21,
    15: 22,
}
"""``commander_state.main_state`` (legacy - v1.13) -> the nav_state of the same mode (gate 11)."""

NAV_TO_MAIN_STATE: dict[int, int] = {nav: main for main, nav in MAIN_STATE_TO_NAV.items()}
