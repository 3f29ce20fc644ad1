"""MAVLink setpoint-field rules (OFB601-OFB607, OFB609) at the edges of the docs' tables."""

from __future__ import annotations

import itertools
import re
from typing import Any

import pytest

from fuzzoff import type_mask as tmask
from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.events import (
    Event,
    Parameter,
    SetActuatorControlTarget,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    VehicleStatus,
)
from fuzzoff.findings import Finding, Severity
from fuzzoff.profiles import Profile
from fuzzoff.tables import mavlink as tm
from tests.helpers import CORPORA
from tests.streams import codes, lint_events

SITL = CORPORA / "sitl"

PAGE_PROFILES = ("1.13", "1.14", "1.15", "1.16", "1.17", "main")
VEHICLES = ("mc", "fw", "vtol", "rover-ackermann", "rover-differential", "rover-mecanum")
ALL_IGNORED = tmask.POSITION_BITS | tmask.VELOCITY_BITS | tmask.ACCELERATION_BITS
NO_YAW = tmask.YAW_IGNORE | tmask.YAW_RATE_IGNORE
POSITION_ONLY_MASK = ALL_IGNORED & ~tmask.POSITION_BITS | NO_YAW
NAN_VALUE = float("nan")


def mask_for(groups: frozenset[str], extra: int = NO_YAW) -> int:
    mask = ALL_IGNORED | extra
    for group in groups:
        mask &= ~tm.GROUP_BITS[group]
    return mask


def setpoint(kind: str, t: float = 0.0, **fields: Any) -> Event:
    if kind == tm.LOCAL:
        return SetPositionTargetLocal(t=t, **fields)
    return SetPositionTargetGlobal(t=t, **fields)


def lint(events: list[Event], px4: str = "1.16", vehicle: str = "mc", **kw: Any) -> list[Finding]:
    return lint_events(events, px4=px4, vehicle=vehicle, fmt="tlog", **kw)


def documented_cases() -> list[tuple[str, str, str, frozenset[str], int]]:
    cases = []
    for px4, vehicle, kind in itertools.product(PAGE_PROFILES, VEHICLES, (tm.LOCAL, tm.GLOBAL)):
        rules = tm.position_rules(Profile(px4=px4, vehicle=vehicle), kind)
        assert rules is not None
        for groups, frames in rules.combos.items():
            for frame in sorted(frames):
                cases.append((px4, vehicle, kind, groups, frame))
    return cases


@pytest.mark.parametrize(("px4", "vehicle", "kind", "groups", "frame"), documented_cases())
def test_every_documented_combination_and_frame_passes_the_docs(
    px4: str, vehicle: str, kind: str, groups: frozenset[str], frame: int
) -> None:
    event = setpoint(kind, type_mask=mask_for(groups), coordinate_frame=frame)
    found = lint([event], px4, vehicle)
    combo_findings = codes(found, "OFB602")
    if kind == tm.LOCAL and frame == 8 and groups == {"position"}:
        # Listed by the docs, but BODY_NED always ignores the position (gate spec 6.2, D17).
        assert [f.severity for f in combo_findings] == [Severity.ERROR]
        assert "docs list this frame" in combo_findings[0].message
        assert "drops the message" in combo_findings[0].message
    else:
        assert not combo_findings
    frame_findings = codes(found, "OFB601")
    if frame in tm.RECEIVER_FRAMES[kind]:
        assert not frame_findings
    else:  # seed 002 lists MAV_FRAME_GLOBAL, which PX4's receiver drops (gate spec D15)
        assert [f.severity for f in frame_findings] == [Severity.ERROR]
        assert "receiver accepts only" in frame_findings[0].message


@pytest.mark.parametrize(
    ("px4", "vehicle", "kind", "groups"),
    [
        ("1.16", "mc", tm.GLOBAL, frozenset({"position", "velocity", "acceleration"})),
        ("1.14", "mc", tm.GLOBAL, frozenset({"position", "velocity", "acceleration"})),
        ("1.16", "mc", tm.LOCAL, frozenset({"velocity", "acceleration"})),
        ("1.16", "mc", tm.LOCAL, frozenset({"position", "acceleration"})),
        ("1.16", "rover-differential", tm.LOCAL, frozenset({"position", "velocity"})),
        ("1.14", "rover-ackermann", tm.GLOBAL, frozenset({"velocity"})),
        ("1.13", "rover-differential", tm.LOCAL, frozenset({"acceleration"})),
    ],
)
def test_undocumented_combination_is_info_on_a_copter_else_a_warning(
    px4: str, vehicle: str, kind: str, groups: frozenset[str]
) -> None:
    """A copter's position controller flies any mix with valid axes (the docs' list alone:
    info); what rover and fixed-wing controllers make of one is unverified (a warning)."""
    frame = 1 if kind == tm.LOCAL else (0 if px4 in ("1.13", "1.14") else 5)
    found = codes(
        lint([setpoint(kind, type_mask=mask_for(groups), coordinate_frame=frame)], px4, vehicle),
        "OFB602",
    )
    expected = Severity.INFO if vehicle == "mc" else Severity.WARNING
    assert [f.severity for f in found] == [expected]
    assert tm.describe_combo(groups) in found[0].message


def test_ignored_groups_are_left_to_their_own_rules() -> None:
    # Fixed-wing position + velocity: velocity is OFB604's (ignored), not a bad combination.
    fw = setpoint(tm.LOCAL, type_mask=12288, coordinate_frame=1, velocity=(10.0, 0.0, 0.0))
    found = lint([fw], vehicle="fw")
    assert not codes(found, "OFB602")
    assert codes(found, "OFB604")
    # Rover velocity + acceleration on 1.16: acceleration is OFB508's.
    mask = mask_for(frozenset({"velocity", "acceleration"}))
    rover = setpoint(tm.LOCAL, type_mask=mask, coordinate_frame=1, acceleration=(1.0, 0.0, 0.0))
    found = lint([rover], vehicle="rover-mecanum")
    assert not codes(found, "OFB602")
    assert codes(found, "OFB508")


@pytest.mark.parametrize("mask", [4095, ALL_IGNORED | NO_YAW, ALL_IGNORED])
def test_mask_selecting_nothing_is_an_error(mask: int) -> None:
    found = codes(lint([setpoint(tm.LOCAL, type_mask=mask, coordinate_frame=1)]), "OFB602")
    assert [f.severity for f in found] == [Severity.ERROR]
    assert "no position, velocity or acceleration" in found[0].message


def test_force_setpoint_is_an_error() -> None:
    mask = mask_for(frozenset({"acceleration"})) | tmask.FORCE_SET
    found = codes(lint([setpoint(tm.LOCAL, type_mask=mask, coordinate_frame=1)]), "OFB602")
    assert [f.severity for f in found] == [Severity.ERROR]
    assert "FORCE" in found[0].message


def test_partial_group_counts_as_that_group() -> None:
    # x, y used and z ignored is still a position setpoint (as the 292 gliding value is).
    mask = mask_for(frozenset({"position"})) | tmask.Z_IGNORE
    event = setpoint(tm.LOCAL, type_mask=mask, coordinate_frame=1)
    assert not codes(lint([event], vehicle="fw"), "OFB602")
    # A multicopter's position controller needs every axis (gate spec 8): that is the finding.
    (found,) = codes(lint([event]), "OFB602")
    assert "axis z has no finite position, velocity or acceleration" in found.message
    assert "not a combination" not in found.message


@pytest.mark.parametrize("vehicle", ["mc", "fw", "rover-differential"])
@pytest.mark.parametrize(
    "ignored", [tmask.X_IGNORE, tmask.Z_IGNORE, tmask.X_IGNORE | tmask.Y_IGNORE]
)
def test_global_int_with_part_of_its_position_is_dropped(vehicle: str, ignored: int) -> None:
    """GLOBAL_INT takes lat, lon and alt only together (gate spec 6.3): on its own, a partial
    position leaves nothing, and PX4 drops the message with its keep-alive."""
    mask = POSITION_ONLY_MASK | ignored
    event = setpoint(tm.GLOBAL, type_mask=mask, coordinate_frame=6)
    (found,) = codes(lint([event], vehicle=vehicle), "OFB602")
    assert found.severity is Severity.ERROR
    assert "ignores all of it" in found.message
    assert "drops the message silently (no setpoint, no keep-alive)" in found.message
    # LOCAL_NED takes its axes one by one: no such finding there
    local = setpoint(tm.LOCAL, type_mask=mask, coordinate_frame=1)
    assert not [f for f in codes(lint([local], vehicle=vehicle), "OFB602") if "whole" in f.message]


def test_global_int_with_part_of_its_position_flies_the_velocity_alone() -> None:
    mask = mask_for(frozenset({"position", "velocity"})) | tmask.Z_IGNORE
    event = setpoint(tm.GLOBAL, type_mask=mask, coordinate_frame=6)
    (found,) = codes(lint([event]), "OFB602")
    assert found.severity is Severity.ERROR
    assert "uses lat_int and lon_int but ignores alt" in found.message
    assert "flies the velocity alone" in found.message


@pytest.mark.parametrize("px4", ["1.13", "1.16", "main"])
def test_global_int_with_the_whole_position_is_clean(px4: str) -> None:
    event = setpoint(tm.GLOBAL, type_mask=POSITION_ONLY_MASK, coordinate_frame=6)
    assert codes(lint([event], px4), "OFB602") == []


@pytest.mark.parametrize(
    ("px4", "mask", "fields", "problem"),
    [
        ("1.16", mask_for(frozenset({"position"})) | 2, {}, "position x and y are not both"),
        ("1.13", mask_for(frozenset({"position"})) | 4, {}, "axis z has no finite"),
        ("1.16", POSITION_ONLY_MASK, {"position": (1.0, NAN_VALUE, -2.0)}, "axis y has no"),
        ("1.16", mask_for(frozenset({"velocity"})) | 16, {}, "velocity x and y are not both"),
    ],
)
def test_copter_setpoint_the_position_controller_rejects(
    px4: str, mask: int, fields: dict[str, Any], problem: str
) -> None:
    event = SetPositionTargetLocal(t=0.0, type_mask=mask, coordinate_frame=1, **fields)
    (found,) = codes(lint([event], px4), "OFB602")
    assert found.severity is Severity.ERROR
    assert problem in found.message
    assert "position controller rejects such a setpoint" in found.message
    fallback = "for up to 200 ms" in found.message
    assert fallback is (px4 == "1.16")
    # The same message is a plain position setpoint for a fixed-wing.
    if mask & tmask.VELOCITY_BITS == tmask.VELOCITY_BITS:
        assert not codes(lint([event], px4, "fw"), "OFB602")


def test_copter_setpoint_with_every_axis_is_clean() -> None:
    # z position with x, y velocity: mixed axes are legal (gate spec 8).
    mask = ALL_IGNORED & ~(tmask.Z_IGNORE | 8 | 16) | NO_YAW
    event = SetPositionTargetLocal(t=0.0, type_mask=mask, coordinate_frame=1)
    assert codes(lint([event]), "OFB602") == []  # position + velocity, a listed combination


@pytest.mark.parametrize(
    ("px4", "vehicle", "kind", "groups", "frame", "severity"),
    [
        ("1.16", "mc", tm.LOCAL, frozenset({"position"}), 7, Severity.ERROR),
        ("1.16", "mc", tm.LOCAL, frozenset({"velocity"}), 9, Severity.ERROR),
        ("1.16", "mc", tm.GLOBAL, frozenset({"position"}), 0, Severity.ERROR),
        ("1.16", "mc", tm.GLOBAL, frozenset({"position"}), 3, Severity.ERROR),
        # the 1.13-1.14 page lists MAV_FRAME_GLOBAL, every release takes 5, 6, 11: docs only
        ("1.13", "mc", tm.GLOBAL, frozenset({"position"}), 5, Severity.INFO),
        ("1.14", "fw", tm.GLOBAL, frozenset({"position"}), 6, Severity.INFO),
        ("1.16", "rover-ackermann", tm.LOCAL, frozenset({"position"}), 8, Severity.ERROR),
        ("1.16", "rover-ackermann", tm.GLOBAL, frozenset({"velocity"}), 1, Severity.ERROR),
    ],
)
def test_unsupported_frame(
    px4: str, vehicle: str, kind: str, groups: frozenset[str], frame: int, severity: Severity
) -> None:
    event = setpoint(kind, type_mask=mask_for(groups) | 12288, coordinate_frame=frame)
    found = codes(lint([event], px4, vehicle), "OFB601")
    assert [f.severity for f in found] == [severity]
    assert tm.frame_name(frame) in found[0].message


def test_rover_velocity_in_body_frame_is_fine() -> None:
    mask = mask_for(frozenset({"velocity"}))
    event = setpoint(tm.LOCAL, type_mask=mask, coordinate_frame=8)
    assert not codes(lint([event], vehicle="rover-differential"), "OFB601")


def test_rules_do_not_apply_without_a_page() -> None:
    event = setpoint(tm.LOCAL, type_mask=4095, coordinate_frame=7)
    found = lint([event], px4="legacy")
    assert not codes(found, "OFB601") and not codes(found, "OFB602")


@pytest.mark.parametrize(
    ("kind", "value"),
    [(tm.LOCAL, v) for v in tm.FIXEDWING_TYPES_LOCAL]
    + [(tm.GLOBAL, v) for v in tm.FIXEDWING_TYPES_GLOBAL],
)
def test_fixedwing_setpoint_types_are_accepted(kind: str, value: int) -> None:
    """Every documented type answers the docs' rule; the takeoff, land and idle types ask for
    an action PX4 (v1.12+) does not take: an error saying so (fw_takeoff_type-*: no runway
    takeoff on 1.16.2, 1.17.0 or the 1.18 head)."""
    mask = value if value != 292 else value | NO_YAW
    frame = 1 if kind == tm.LOCAL else 5
    event = setpoint(kind, type_mask=mask, coordinate_frame=frame)
    found = codes(lint([event], vehicle="fw"), "OFB603")
    if tm.FIXEDWING_TYPES_LOCAL[value] in ("takeoff", "land", "idle"):
        assert [f.severity for f in found] == [Severity.ERROR]
        assert "does not read the type bits" in found[0].message
        assert "flower" not in found[0].message
        assert not codes(lint([event], "legacy", "fw"), "OFB603")  # OFB609's there
    else:
        assert not found


@pytest.mark.parametrize(
    ("px4", "kind", "mask", "severity"),
    [
        # v1.12+ do not read these bits (D14): the docs' rule alone, info
        ("1.16", tm.LOCAL, 3576, Severity.INFO),
        ("1.13", tm.GLOBAL, 3576, Severity.INFO),
        ("1.16", tm.GLOBAL, 292, Severity.INFO),  # 292 is a LOCAL_NED value only
        ("1.16", tm.LOCAL, 0x5000, Severity.INFO),  # not one of the values
        ("legacy", tm.LOCAL, 3576, Severity.ERROR),
        ("1.11", tm.GLOBAL, 0, Severity.ERROR),
    ],
)
def test_fixedwing_position_without_type(
    px4: str, kind: str, mask: int, severity: Severity
) -> None:
    frame = 1 if kind == tm.LOCAL else 5
    found = codes(
        lint([setpoint(kind, type_mask=mask, coordinate_frame=frame)], px4, "fw"), "OFB603"
    )
    assert [f.severity for f in found] == [severity]
    assert "flower" in found[0].message


def test_fixedwing_type_not_needed_without_position_or_on_a_copter() -> None:
    velocity_only = setpoint(tm.LOCAL, type_mask=3527, coordinate_frame=1)
    assert not codes(lint([velocity_only], vehicle="fw"), "OFB603")
    copter = setpoint(tm.LOCAL, type_mask=3576, coordinate_frame=1)
    assert not codes(lint([copter], vehicle="mc"), "OFB603")


def test_a_fixedwing_velocity_without_a_position_is_an_error_beside_one_a_warning() -> None:
    """OFB604: a velocity alone is not flown in FW flight (vtol_fw_velocity-*: no turn); beside
    a position the docs say it is ignored (1.14-1.17 follow a path along it)."""
    alone = setpoint(tm.LOCAL, type_mask=3527, coordinate_frame=1, velocity=(0, 10.0, 0))
    (finding,) = codes(lint([alone], vehicle="fw"), "OFB604")
    assert finding.severity == Severity.ERROR and "does not fly it" in finding.message
    beside = setpoint(tm.LOCAL, type_mask=12288, coordinate_frame=1, velocity=(15.0, 0, 0))
    (finding,) = codes(lint([beside], vehicle="fw"), "OFB604")
    assert finding.severity == Severity.WARNING


def test_fixedwing_velocity_and_acceleration_values_are_reported_as_ignored() -> None:
    zeros = setpoint(tm.GLOBAL, type_mask=4096, coordinate_frame=5)
    assert not codes(lint([zeros], vehicle="fw"), "OFB604")
    accel = setpoint(tm.GLOBAL, type_mask=4096, coordinate_frame=5, acceleration=(0, 0, 2.0))
    (finding,) = codes(lint([accel], vehicle="fw"), "OFB604")
    assert "afz" in finding.message and finding.severity is Severity.WARNING
    ignored_bit = setpoint(tm.LOCAL, type_mask=4096 | 8, coordinate_frame=1, velocity=(5, 0, 0))
    assert not codes(lint([ignored_bit], vehicle="fw"), "OFB604")


def test_global_acceleration_on_a_copter() -> None:
    mask = mask_for(frozenset({"acceleration"}))
    found = codes(lint([setpoint(tm.GLOBAL, type_mask=mask, coordinate_frame=5)]), "OFB605")
    assert [f.severity for f in found] == [Severity.WARNING]
    local = setpoint(tm.LOCAL, type_mask=mask, coordinate_frame=1)
    assert not codes(lint([local]), "OFB605")
    velocity = setpoint(tm.GLOBAL, type_mask=mask_for(frozenset({"velocity"})), coordinate_frame=5)
    assert not codes(lint([velocity]), "OFB605")


@pytest.mark.parametrize(
    ("mask", "expected"),
    [
        (7, []),  # attitude + thrust
        (128, []),  # body rates + thrust
        (4 | 128, []),  # roll and pitch rate + thrust
        (7 | 64 | 32, []),  # thrust through thrust_body
        (7 | 128, ["neither"]),
        (1 | 128, ["neither"]),
        (7 | 64, ["thrust"]),
        (7 | 64 | 128, ["neither", "thrust"]),
    ],
)
def test_attitude_target_masks(mask: int, expected: list[str]) -> None:
    found = codes(lint([SetAttitudeTarget(t=0.0, type_mask=mask)]), "OFB606")
    words = {"neither": "ignores both", "thrust": "ignores the thrust"}
    assert len(found) == len(expected)
    for key in expected:
        assert any(words[key] in f.message for f in found)


def test_attitude_without_thrust_says_what_the_version_does() -> None:
    (old,) = codes(lint([SetAttitudeTarget(t=0.0, type_mask=71)], px4="1.17"), "OFB606")
    assert "thrust of 0" in old.message
    (new,) = codes(lint([SetAttitudeTarget(t=0.0, type_mask=71)], px4="main"), "OFB606")
    assert "ignores such a message entirely" in new.message


def test_attitude_target_on_a_new_rover_is_left_to_ofb507() -> None:
    found = lint([SetAttitudeTarget(t=0.0, type_mask=71)], vehicle="rover-differential")
    assert not codes(found, "OFB606")
    assert codes(found, "OFB507")


def test_a_repeated_mistake_is_one_finding_per_stretch() -> None:
    bad = [setpoint(tm.LOCAL, t=i * 0.05, type_mask=3576, coordinate_frame=7) for i in range(20)]
    good = [
        setpoint(tm.LOCAL, t=1.0 + i * 0.05, type_mask=3576, coordinate_frame=1) for i in range(5)
    ]
    again = [setpoint(tm.LOCAL, t=2.5, type_mask=3576, coordinate_frame=7)]
    found = codes(lint(bad + good + again), "OFB601")
    assert [f.time_s for f in found] == [0.0, 2.5]
    assert found[0].end_s == pytest.approx(0.95)
    assert "20 messages" in found[0].message


def test_good_messages_between_bad_ones_do_not_split_the_stretch() -> None:
    events = [
        setpoint(tm.LOCAL, t=i * 0.05, type_mask=3576, coordinate_frame=7 if i % 2 else 1)
        for i in range(40)
    ]
    (finding,) = codes(lint(events), "OFB601")
    assert finding.time_s == pytest.approx(0.05) and finding.end_s == pytest.approx(1.95)


def heartbeat(t: float, vehicle: str = "1") -> VehicleStatus:
    return VehicleStatus(t=t, vehicle=vehicle, nav_state=2)


def aimed(t: float, system: int, component: int = 1, vehicle: str = "1", **kw: Any) -> Event:
    return SetPositionTargetLocal(
        t=t,
        vehicle=vehicle,
        target_system=system,
        target_component=component,
        type_mask=3576,
        coordinate_frame=1,
        **kw,
    )


@pytest.mark.parametrize(
    ("system", "component", "wrong"),
    [(1, 1, False), (0, 0, False), (1, 0, False), (0, 1, False), (2, 1, True), (1, 191, True)],
)
def test_setpoint_target(system: int, component: int, wrong: bool) -> None:
    found = codes(lint([heartbeat(0.0), aimed(0.5, system, component)]), "OFB607")
    assert bool(found) is wrong


def test_setpoints_before_the_first_heartbeat_are_judged_once_it_comes() -> None:
    events = [aimed(0.1 * i, 3) for i in range(5)] + [heartbeat(0.45)]
    events += [aimed(0.5 + 0.1 * i, 3) for i in range(3)]
    (finding,) = codes(lint(events), "OFB607")
    assert finding.time_s == 0.0 and finding.end_s == pytest.approx(0.7)
    assert "target_system 3" in finding.message


def test_sysid_parameter_names_the_vehicle() -> None:
    events = [Parameter(t=0.0, vehicle="1", name="MAV_SYS_ID", value=4.0), aimed(0.1, 1)]
    assert codes(lint(events), "OFB607")


def test_no_vehicle_messages_means_not_checkable() -> None:
    found = lint([aimed(0.0, 2), aimed(0.1, 2)])
    assert not codes(found, "OFB607")
    (note,) = [f for f in codes(found, "OFB002") if "OFB607" in f.message]
    assert "HEARTBEAT" in note.message


def test_mavros_setpoints_carry_no_target_to_judge() -> None:
    event = SetPositionTargetLocal(
        t=0.5, vehicle="1", target_system=9, transport="mavros", type_mask=3576
    )
    found = lint([heartbeat(0.0), event])
    assert not codes(found, "OFB607")
    assert not [f for f in codes(found, "OFB002") if "OFB607" in f.message]


def test_user_can_turn_a_rule_off() -> None:
    settings = Settings(ignore=frozenset({"OFB601"}))
    event = setpoint(tm.LOCAL, type_mask=3576, coordinate_frame=7)
    assert not codes(lint([event], settings=settings), "OFB601")


# -- OFB602: BODY_NED keeps no position (gate spec 6.2, D17) ---------------------------------

POSITION_ONLY = mask_for(frozenset({"position"}))


@pytest.mark.parametrize(
    ("mask", "dropped"),
    [
        (POSITION_ONLY, True),
        (POSITION_ONLY & ~tmask.YAW_IGNORE, True),  # with a yaw: still nothing the receiver keeps
        (mask_for(frozenset({"velocity"})) | tmask.VZ_IGNORE, True),  # vx, vy only: no velocity
        (mask_for(frozenset({"acceleration"})) | tmask.AZ_IGNORE, True),
        (mask_for(frozenset({"velocity"})), False),
        (mask_for(frozenset({"position", "velocity"})), False),
    ],
)
def test_body_ned_message_the_receiver_empties_is_an_error(mask: int, dropped: bool) -> None:
    event = SetPositionTargetLocal(t=0.0, type_mask=mask, coordinate_frame=8)
    found = codes(lint([event]), "OFB602")
    if not dropped:
        assert found == []
        return
    (finding,) = found
    assert finding.severity is Severity.ERROR
    assert "MAV_FRAME_BODY_NED (8)" in finding.message
    assert "docs list this frame" in finding.message
    assert "PX4 drops the message (no setpoint, no keep-alive)" in finding.message
    # In LOCAL_NED the receiver keeps the same mask (a partial vector is then the position
    # controller's problem, not a drop).
    local = SetPositionTargetLocal(t=0.0, type_mask=mask, coordinate_frame=1)
    assert not [f for f in codes(lint([local]), "OFB602") if "drops" in f.message]


def test_body_ned_position_of_a_rover_is_ofb601_alone() -> None:
    event = SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY, coordinate_frame=8)
    found = lint([event], vehicle="rover-ackermann")
    assert codes(found, "OFB602") == []
    (frame,) = codes(found, "OFB601")
    assert "ignores the position in this frame and, with nothing else left, drops" in (
        frame.message
    )


# -- OFB609: the legacy / 1.11 receiver -----------------------------------------------------

NAN = float("nan")
INF = float("inf")


@pytest.mark.parametrize(
    ("event", "words"),
    [
        (
            SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY, velocity=(NAN, NAN, NAN)),
            "non-finite vx, vy, vz",
        ),
        (
            SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY | tmask.YAW_IGNORE, yaw=NAN),
            "non-finite yaw",
        ),
        (
            SetPositionTargetLocal(t=0.0, type_mask=mask_for(frozenset(), 512 | NO_YAW)),
            "FORCE bit",
        ),
        (SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY | 4096), "takeoff (4096)"),
        (SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY | 8192), "land (8192)"),
        (SetAttitudeTarget(t=0.0, type_mask=7, thrust=0.5, q=(NAN, 0.0, 0.0, 0.0)), "q[0]"),
        (SetAttitudeTarget(t=0.0, type_mask=128, thrust=0.5, body_yaw_rate=INF), "yaw"),
        (SetPositionTargetGlobal(t=0.0, type_mask=POSITION_ONLY), "not handled"),
    ],
)
def test_legacy_receiver_drops(event: Event, words: str) -> None:
    (found,) = codes(lint([event], px4="legacy"), "OFB609")
    assert found.severity is Severity.ERROR
    assert words in found.message
    # No docs page covers these versions, and 1.13+ has its own rules.
    assert codes(lint([event], px4="1.13"), "OFB609") == []


@pytest.mark.parametrize(
    "event",
    [
        SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY, position=(1.0, 2.0, -3.0)),
        SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY | 12288),
        SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY | 16384),
        SetPositionTargetLocal(t=0.0, type_mask=POSITION_ONLY, yaw_rate=NAN),  # not checked
        SetPositionTargetLocal(t=0.0, type_mask=mask_for(frozenset({"position"}), 512)),
        SetAttitudeTarget(t=0.0, type_mask=7, thrust=0.5),
    ],
)
def test_legacy_receiver_takes(event: Event) -> None:
    assert codes(lint([event], px4="legacy"), "OFB609") == []
    assert codes(lint([event], px4="1.11"), "OFB609") == []


def test_global_int_on_1_11_is_a_warning_that_says_unverified() -> None:
    event = SetPositionTargetGlobal(t=0.0, type_mask=POSITION_ONLY)
    (found,) = codes(lint([event], px4="1.11"), "OFB609")
    assert found.severity is Severity.WARNING
    assert "unverified" in found.message


def test_legacy_drops_are_one_finding_per_stretch() -> None:
    events: list[Event] = [
        SetPositionTargetLocal(t=i * 0.1, type_mask=POSITION_ONLY, velocity=(NAN, NAN, NAN))
        for i in range(20)
    ]
    (found,) = codes(lint(events, px4="legacy"), "OFB609")
    assert found.time_s == 0.0
    assert found.end_s == pytest.approx(1.9)


# -- OFB608: messages PX4 has no handler for (gate spec 6.6) ----------------------------------


def actuators(start: float, stop: float, groups: tuple[int, ...] = (0, 1)) -> list[Event]:
    """MAVSDK's set_actuator_control: one message per group every 50 ms."""
    n = round((stop - start) / 0.05)
    return [
        SetActuatorControlTarget(
            t=round(start + i * 0.05, 3),
            vehicle="1",
            target_system=1,
            target_component=1,
            group_mlx=group,
        )
        for i in range(n)
        for group in groups
    ]


def test_ofb608_one_finding_per_stretch_with_how_many_and_how_many_in_offboard() -> None:
    in_offboard = VehicleStatus(t=0.5, vehicle="1", nav_state=14, armed=True)
    left = VehicleStatus(t=1.5, vehicle="1", nav_state=2, armed=True)
    events = [heartbeat(0.0), in_offboard, left, *actuators(1.0, 2.0), *actuators(4.0, 4.5)]
    first, second = codes(lint(events), "OFB608")
    assert first.severity is Severity.ERROR
    assert (first.time_s, first.end_s) == (1.0, pytest.approx(1.95))
    assert first.short.startswith("40 SET_ACTUATOR_CONTROL_TARGET ignored by PX4 1.16")
    assert "(20 in OFFBOARD)" in first.message and "no keep-alive" in first.message
    # a pause of over a second starts a new stretch
    assert second.time_s == 4.0 and second.short.startswith("20 SET_ACTUATOR_CONTROL_TARGET")
    assert "in OFFBOARD" not in second.message


@pytest.mark.parametrize(("px4", "fires"), [("1.13", False), ("1.14", True), ("main", True)])
def test_ofb608_only_where_px4_has_no_handler(px4: str, fires: bool) -> None:
    events = [heartbeat(0.0), *actuators(1.0, 1.2)]
    assert bool(codes(lint(events, px4=px4), "OFB608")) is fires


def test_ofb101_names_the_ignored_messages_that_came_in_the_gap() -> None:
    """MAVSDK in OFFBOARD switched from a velocity setpoint to set_actuator_control: the
    keep-alive stops, and the gap says what PX4 did with the 40 Hz that kept coming."""
    status = [VehicleStatus(t=t, vehicle="1", nav_state=14, armed=True) for t in (0.0, 1.0, 2.0)]
    velocity = [aimed(round(0.05 * i, 3), 1) for i in range(21)]
    events = [*status, *velocity, *actuators(1.05, 2.55)]
    events.append(VehicleStatus(t=3.0, vehicle="1", nav_state=2, armed=True))
    (gap,) = codes(lint(events), "OFB101")
    assert gap.short.endswith("; 60 SET_ACTUATOR_CONTROL_TARGET in it, ignored")
    assert "in the gap came 60 SET_ACTUATOR_CONTROL_TARGET, which PX4 1.16 ignores" in gap.message
    # on 1.13 PX4 handles them (fuzzoff does not count them as keep-alive there): not said
    (older,) = codes(lint(events, px4="1.13"), "OFB101")
    assert "SET_ACTUATOR_CONTROL_TARGET" not in older.message


def test_real_mavsdk_set_actuator_control_on_px4_1_16_2() -> None:
    """MAVSDK 4.1 hovering in OFFBOARD on a velocity setpoint calls set_actuator_control (real
    PX4 1.16.2 SITL, corpora/sitl): the keep-alive gap says what PX4 did with the 40 Hz of
    SET_ACTUATOR_CONTROL_TARGET in it, and OFB608 names the stretch; PX4's own log (its
    failsafe flag) shows the loss."""
    tlog = lint_file(SITL / "mavsdk4_actuator-1.16.2.tlog").findings
    (gap,) = codes(tlog, "OFB101")
    assert re.search(r"; \d+ SET_ACTUATOR_CONTROL_TARGET in it, ignored$", gap.short), gap.short
    (ignored,) = codes(tlog, "OFB608")
    assert ignored.severity is Severity.ERROR and "in OFFBOARD)" in ignored.message
    assert codes(tlog, "OFB103")
    ulog = lint_file(SITL / "mavsdk4_actuator-1.16.2.ulg").findings
    (logged_gap,) = codes(ulog, "OFB101")
    assert "the companion's side of the link" in logged_gap.message
    assert codes(ulog, "OFB103") and not codes(ulog, "OFB608")  # no trace in PX4's own log
