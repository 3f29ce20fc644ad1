"""What the docs allow in MAVLink offboard setpoints, per page, message and vehicle (OFB5xx/6xx).

Seed 000 "MAVLink Offboard Control" (current page) judges PX4 1.15 and newer; seed 002
"MAVLink 消息" (the v1.13-v1.14 page) judges 1.13 and 1.14. No seed documents the MAVLink
fields of ``legacy`` or ``1.11``, so these rules do not apply there. The choice of page for
1.15 (which sits between the two) is ours: the current page matches what 1.15's receiver does.

A ``type_mask`` selects groups: position (bits 0-2), velocity (bits 3-5), acceleration or force
(bits 6-8); a component is used when its ignore bit is clear, and a group is selected when any
of its components is used. Yaw (bit 10) and yaw rate (bit 11) may accompany any combination.
Bits 12-14 carry the fixed-wing "setpoint type" values, which are not part of MAVLink.

``RECEIVER_FRAMES`` is the one code fact kept here (gate.md#receiver): the frames PX4's
receiver accepts in v1.12-main, so OFB601 can say where the docs and the code disagree.
"""

from __future__ import annotations

from dataclasses import field

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import Profile
from fuzzoff.type_mask import (
    ACCELERATION_BITS,
    ATTITUDE_IGNORE,
    AZ_IGNORE,
    PITCH_RATE_IGNORE,
    POSITION_BITS,
    ROLL_RATE_IGNORE,
    SETPOINT_TYPE_BITS,
    THROTTLE_IGNORE,
    THRUST_BODY_SET,
    VELOCITY_BITS,
    VZ_IGNORE,
    Z_IGNORE,
)

GROUP_BITS: dict[str, int] = {
    "position": POSITION_BITS,
    "velocity": VELOCITY_BITS,
    "acceleration": ACCELERATION_BITS,
}
GROUP_ORDER = ("position", "velocity", "acceleration")

FRAME_NAMES: dict[int, str] = {
    0: "MAV_FRAME_GLOBAL",
    1: "MAV_FRAME_LOCAL_NED",
    2: "MAV_FRAME_MISSION",
    3: "MAV_FRAME_GLOBAL_RELATIVE_ALT",
    4: "MAV_FRAME_LOCAL_ENU",
    5: "MAV_FRAME_GLOBAL_INT",
    6: "MAV_FRAME_GLOBAL_RELATIVE_ALT_INT",
    7: "MAV_FRAME_LOCAL_OFFSET_NED",
    8: "MAV_FRAME_BODY_NED",
    9: "MAV_FRAME_BODY_OFFSET_NED",
    10: "MAV_FRAME_GLOBAL_TERRAIN_ALT",
    11: "MAV_FRAME_GLOBAL_TERRAIN_ALT_INT",
    12: "MAV_FRAME_BODY_FRD",
    20: "MAV_FRAME_LOCAL_FRD",
    21: "MAV_FRAME_LOCAL_FLU",
}

LOCAL = "set_position_target_local_ned"
GLOBAL = "set_position_target_global_int"
ATTITUDE = "set_attitude_target"

MESSAGE_NAMES = {
    LOCAL: "SET_POSITION_TARGET_LOCAL_NED",
    GLOBAL: "SET_POSITION_TARGET_GLOBAL_INT",
    ATTITUDE: "SET_ATTITUDE_TARGET",
}

FIXEDWING_TYPES_LOCAL: dict[int, str] = {
    292: "gliding",
    4096: "takeoff",
    8192: "land",
    12288: "loiter",
    16384: "idle",
}
"""Seed 000/002 "Fixed-wing": setpoint-type values of SET_POSITION_TARGET_LOCAL_NED."""

FIXEDWING_TYPES_GLOBAL: dict[int, str] = {
    k: v for k, v in FIXEDWING_TYPES_LOCAL.items() if k != 292
}
"""SET_POSITION_TARGET_GLOBAL_INT lists the same values without 292."""

RECEIVER_FRAMES: dict[str, frozenset[int]] = {
    LOCAL: frozenset({1, 8}),
    GLOBAL: frozenset({5, 6, 11}),
}
"""Code, not docs (gate.md#receiver, v1.12-main): any other frame is dropped, no keep-alive."""

Combo = frozenset[str]


def combo(*groups: str) -> Combo:
    return frozenset(groups)


@dataclass(frozen=True, slots=True)
class PositionTargetRules:
    """The docs' rules for one SET_POSITION_TARGET_* message on one vehicle group and page."""

    combos: dict[Combo, frozenset[int]]
    """Supported combinations -> the coordinate frames allowed with each."""
    ignored: frozenset[str] = frozenset()
    """Groups the vehicle ignores (its own rule: OFB604 fixed-wing, OFB508 rover)."""
    setpoint_types: dict[int, str] = field(default_factory=dict)
    """Required fixed-wing setpoint-type values (OFB603); empty = none required."""

    @property
    def frames(self) -> frozenset[int]:
        """Every frame the message accepts, whatever the combination."""
        out: frozenset[int] = frozenset()
        for frames in self.combos.values():
            out |= frames
        return out

    def frames_for(self, selected: Combo) -> frozenset[int]:
        return self.combos.get(selected, self.frames)


@dataclass(frozen=True, slots=True)
class AttitudeTargetRules:
    """SET_ATTITUDE_TARGET on one vehicle group and page."""

    supported: bool
    rates: bool = True
    """Body-rate setpoints (with thrust) are a listed combination."""
    yaw_only: bool = False
    """Only the yaw of the attitude is used (seed 002, rover)."""


@dataclass(frozen=True, slots=True)
class MavlinkPage:
    doc: str
    section: str
    local: dict[str, PositionTargetRules]
    global_int: dict[str, PositionTargetRules]
    attitude: dict[str, AttitudeTargetRules]

    def position_rules(self, kind: str, group: str) -> PositionTargetRules:
        return (self.local if kind == LOCAL else self.global_int)[group]


_LOCAL_FRAMES = frozenset({1, 8})
_GLOBAL_INT_FRAMES = frozenset({5, 6, 11})
_GLOBAL_FRAMES = frozenset({0})

_COPTER_LOCAL = {
    combo("position"): _LOCAL_FRAMES,
    combo("velocity"): _LOCAL_FRAMES,
    combo("acceleration"): _LOCAL_FRAMES,
    combo("position", "velocity"): _LOCAL_FRAMES,
    combo("position", "velocity", "acceleration"): _LOCAL_FRAMES,
}


def _copter_global(frames: frozenset[int]) -> dict[Combo, frozenset[int]]:
    return {
        combo("position"): frames,
        combo("velocity"): frames,
        combo("acceleration"): frames,
        combo("position", "velocity"): frames,
    }


_FW_IGNORED = frozenset({"velocity", "acceleration"})

PAGE_000 = MavlinkPage(
    doc="000",
    section="MAVLink Offboard Control",
    local={
        "copter": PositionTargetRules(_COPTER_LOCAL),
        "fixedwing": PositionTargetRules(
            {combo("position"): _LOCAL_FRAMES}, _FW_IGNORED, FIXEDWING_TYPES_LOCAL
        ),
        "rover": PositionTargetRules(
            {combo("position"): frozenset({1}), combo("velocity"): _LOCAL_FRAMES},
            frozenset({"acceleration"}),
        ),
    },
    global_int={
        "copter": PositionTargetRules(_copter_global(_GLOBAL_INT_FRAMES)),
        "fixedwing": PositionTargetRules(
            {combo("position"): _GLOBAL_INT_FRAMES}, _FW_IGNORED, FIXEDWING_TYPES_GLOBAL
        ),
        "rover": PositionTargetRules(
            {combo("position"): _GLOBAL_INT_FRAMES, combo("velocity"): _GLOBAL_INT_FRAMES},
            frozenset({"acceleration"}),
        ),
    },
    attitude={
        "copter": AttitudeTargetRules(True),
        "fixedwing": AttitudeTargetRules(True),
        "rover": AttitudeTargetRules(False),
    },
)

PAGE_002 = MavlinkPage(
    doc="002",
    section="MAVLink 消息",
    local={
        "copter": PositionTargetRules(_COPTER_LOCAL),
        "fixedwing": PositionTargetRules(
            {combo("position"): _LOCAL_FRAMES}, _FW_IGNORED, FIXEDWING_TYPES_LOCAL
        ),
        "rover": PositionTargetRules(
            {combo("position"): _LOCAL_FRAMES, combo("velocity"): _LOCAL_FRAMES}
        ),
    },
    global_int={
        "copter": PositionTargetRules(_copter_global(_GLOBAL_FRAMES)),
        "fixedwing": PositionTargetRules(
            {combo("position"): _GLOBAL_FRAMES}, _FW_IGNORED, FIXEDWING_TYPES_GLOBAL
        ),
        "rover": PositionTargetRules({combo("position"): _GLOBAL_FRAMES}),
    },
    attitude={
        "copter": AttitudeTargetRules(True),
        "fixedwing": AttitudeTargetRules(True),
        "rover": AttitudeTargetRules(True, rates=False, yaw_only=True),
    },
)

PAGES: dict[str, MavlinkPage] = {"002": PAGE_002, "000": PAGE_000}
"""The pages by seed; a release names its own (``Release.docs_page``)."""

ROVER_YAW_IGNORED = frozenset({"rover-ackermann", "rover-differential"})
"""Seed 000 "Ровер" (MAVLink): yaw and yaw rate are ignored; mecanum uses them."""


def vehicle_group(vehicle: str) -> str:
    """The docs' headings: copter/VTOL, fixed-wing, rover."""
    if vehicle == "fw":
        return "fixedwing"
    if vehicle.startswith("rover"):
        return "rover"
    return "copter"


def page_for(profile: Profile) -> MavlinkPage | None:
    """The docs page that judges this profile's MAVLink fields (None: no page covers it)."""
    page = profile.release.docs_page
    return None if page is None else PAGES[page]


def position_rules(profile: Profile, kind: str) -> PositionTargetRules | None:
    page = page_for(profile)
    if page is None:
        return None
    return page.position_rules(kind, vehicle_group(profile.vehicle))


def attitude_rules(profile: Profile) -> AttitudeTargetRules | None:
    page = page_for(profile)
    if page is None:
        return None
    return page.attitude[vehicle_group(profile.vehicle)]


def used(type_mask: int, bits: int) -> bool:
    """Is any component of ``bits`` used (its ignore bit clear)?"""
    return type_mask & bits != bits


def selected_groups(type_mask: int) -> Combo:
    """The position / velocity / acceleration groups a type_mask selects."""
    return frozenset(g for g, bits in GROUP_BITS.items() if used(type_mask, bits))


def body_ned_groups(type_mask: int) -> Combo:
    """What PX4's receiver keeps of a LOCAL_NED in MAV_FRAME_BODY_NED (gate.md#receiver,
    #docs-vs-code): never the position; a velocity or acceleration only with all three components
    used."""
    return frozenset(g for g in ("velocity", "acceleration") if not type_mask & GROUP_BITS[g])


def describe_combo(groups: Combo) -> str:
    if not groups:
        return "nothing"
    return " + ".join(g for g in GROUP_ORDER if g in groups)


def frame_name(frame: int) -> str:
    return FRAME_NAMES.get(frame, f"frame {frame}")


def setpoint_type(type_mask: int, kind: str) -> str | None:
    """The fixed-wing setpoint-type name the mask carries, or None."""
    values = FIXEDWING_TYPES_LOCAL if kind == LOCAL else FIXEDWING_TYPES_GLOBAL
    bits = type_mask & SETPOINT_TYPE_BITS
    if bits in values:
        return values[bits]
    gliding = Z_IGNORE | VZ_IGNORE | AZ_IGNORE
    if kind == LOCAL and bits == 0 and type_mask & gliding == gliding:
        return values[292]
    return None


def attitude_used(type_mask: int) -> bool:
    return not type_mask & ATTITUDE_IGNORE


def rates_used(type_mask: int) -> bool:
    """Body rates count as given when roll and pitch rate are used (gate.md#receiver)."""
    return not type_mask & (ROLL_RATE_IGNORE | PITCH_RATE_IGNORE)


def thrust_used(type_mask: int) -> bool:
    return not type_mask & THROTTLE_IGNORE or bool(type_mask & THRUST_BODY_SET)
