"""PX4 mode numbering across sources: nav_state, MAVLink custom modes, MAVROS mode strings.

Gate spec section 11 and formats.md 7.3: HEARTBEAT ``custom_mode = main << 16 | sub << 24``.
"""

from __future__ import annotations

NAV_STATE_NAMES: dict[int, str] = {
    0: "MANUAL",
    1: "ALTCTL",
    2: "POSCTL",
    3: "AUTO_MISSION",
    4: "AUTO_LOITER",
    5: "AUTO_RTL",
    6: "POSITION_SLOW",
    7: "GUIDED_COURSE",
    8: "ALTITUDE_CRUISE",
    9: "AUTO_LANDGPSFAIL",
    10: "ACRO",
    12: "DESCEND",
    13: "TERMINATION",
    14: "OFFBOARD",
    15: "STAB",
    16: "RATTITUDE",
    17: "AUTO_TAKEOFF",
    18: "AUTO_LAND",
    19: "AUTO_FOLLOW_TARGET",
    20: "AUTO_PRECLAND",
    21: "ORBIT",
    22: "AUTO_VTOL_TAKEOFF",
    **{23 + i: f"EXTERNAL{i + 1}" for i in range(8)},
}

# (main_mode, sub_mode) -> nav_state; sub_mode 0 means "any sub mode" for that main mode.
_CUSTOM_TO_NAV: dict[tuple[int, int], int] = {
    (1, 0): 0,
    (2, 0): 1,
    (3, 0): 2,
    (3, 1): 2,
    (3, 2): 21,
    (3, 3): 6,
    (4, 1): 4,
    (4, 2): 17,
    (4, 3): 4,
    (4, 4): 3,
    (4, 5): 5,
    (4, 6): 18,
    (4, 8): 19,
    (4, 9): 20,
    (4, 10): 22,
    (4, 19): 7,  # GUIDED_COURSE, 1.18+ (gate spec 16 S10)
    (4, 20): 12,  # DESCEND as main reports it (16 S10); 1.18 and older report AUTO_LAND's
    (5, 0): 10,
    (6, 0): 14,
    (7, 0): 15,
    (8, 0): 16,
    (10, 0): 13,
}

_NAV_TO_CUSTOM: dict[int, tuple[int, int]] = {
    0: (1, 0),
    1: (2, 0),
    2: (3, 0),
    3: (4, 4),
    4: (4, 3),
    5: (4, 5),
    6: (3, 3),
    7: (4, 19),
    10: (5, 0),
    12: (4, 6),
    13: (10, 0),
    14: (6, 0),
    15: (7, 0),
    16: (8, 0),
    17: (4, 2),
    18: (4, 6),
    19: (4, 8),
    20: (4, 9),
    21: (3, 2),
    22: (4, 10),
}

MAVROS_MODES: dict[str, int] = {
    "MANUAL": 0,
    "ALTCTL": 1,
    "POSCTL": 2,
    "AUTO.MISSION": 3,
    "AUTO.LOITER": 4,
    "AUTO.RTL": 5,
    "ACRO": 10,
    "OFFBOARD": 14,
    "STABILIZED": 15,
    "RATTITUDE": 16,
    "AUTO.TAKEOFF": 17,
    "AUTO.LAND": 18,
    "AUTO.FOLLOW_TARGET": 19,
    "AUTO.PRECLAND": 20,
    "AUTO.READY": 4,
    "AUTO.RTGS": 5,
}


def nav_state_name(nav_state: int | None) -> str:
    if nav_state is None:
        return "unknown"
    return NAV_STATE_NAMES.get(nav_state, f"nav_state {nav_state}")


def split_custom_mode(custom_mode: int) -> tuple[int, int]:
    """(main_mode, sub_mode) of a PX4 HEARTBEAT ``custom_mode``."""
    return (custom_mode >> 16) & 0xFF, (custom_mode >> 24) & 0xFF


def custom_mode_to_nav_state(custom_mode: int) -> int | None:
    main, sub = split_custom_mode(custom_mode)
    return _CUSTOM_TO_NAV.get((main, sub), _CUSTOM_TO_NAV.get((main, 0)))


def nav_state_to_custom_mode(nav_state: int) -> int:
    """The HEARTBEAT ``custom_mode`` PX4 reports for ``nav_state`` (0 if it has none)."""
    main, sub = _NAV_TO_CUSTOM.get(nav_state, (0, 0))
    return (main << 16) | (sub << 24)


def mavros_mode_to_nav_state(mode: str) -> int | None:
    return MAVROS_MODES.get(mode.strip().upper())


def nav_state_to_mavros_mode(nav_state: int) -> str:
    for name, value in MAVROS_MODES.items():
        if value == nav_state:
            return name
    return "MANUAL"
