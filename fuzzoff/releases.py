"""One record per modelled PX4 release: what the gate, the checks, the readers and the writers ask.

Each record answers questions about behaviour ("does Commander accept a switch to OFFBOARD while
disarmed without a stream?"), never "is this release at least 1.14?": code asks
``release.accepts_disarmed_switch``, and a new PX4 release is one new record here (plus its
``px4_msgs`` folder), each field written down once, beside the docs/gate.md
section it comes from.

A record is found once, where a model or a check is built (``get``, ``Profile.release``), never per
event. The table is read at call time (``names``, ``get``, ``RELEASES``), so a record added here is
known to ``--px4``, ``fuzzoff profiles``, the rule catalog's ``1.13+`` and the fuzz strategies.

This module imports nothing from fuzzoff: every layer may ask it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import field, replace
from types import MappingProxyType
from typing import Literal

from fuzzoff.lean_dataclass import dataclass

PX4Profile = Literal["legacy", "1.11", "1.13", "1.14", "1.15", "1.16", "1.17", "1.18", "main"]
"""The names of the modelled releases (``--px4`` values), oldest first."""

LossSignal = Literal["fixed", "age", "hysteresis", "tick"]
"""How PX4 decides the offboard signal is lost (gate.md#signal)."""

LossFailsafe = Literal["state_machine_legacy", "state_machine", "framework"]
"""What picks the action on offboard loss (gate.md#loss)."""

NavRclFallback = Literal["none", "before_degrade", "after_degrade"]
"""Where a stick mode chosen on offboard loss without manual control becomes NAV_RCL_ACT
(gate.md#loss): never, before the PosCtrl -> AltCtrl -> Stab chain, or after it."""

UnsupportedModeAnswer = Literal["rejected_unverified", "acked_no_change", "rejected"]
"""Commander's answer to DO_SET_MODE with a custom main mode it does not know (gate.md#requests)."""

ControlModeLayout = Literal["ignore_fields", "actuator", "thrust_and_torque"]
"""OffboardControlMode's fields: legacy ``ignore_*``, 1.13's booleans with one ``actuator``,
1.15's ``thrust_and_torque`` and ``direct_actuator`` (gate.md#control-mode)."""

AlienCommandAnswer = Literal["ack_failed", "ignored"]
"""What PX4's MAVLink receiver does with a command it is not addressed by (4.4)."""

DocsPage = Literal["002", "000"]
"""The PX4 docs page (seed) that states the offboard rules of a release."""

StickOverride = Literal["none", "com_rc_override", "man_override_spd"]
"""What ends OFFBOARD when the pilot moves the sticks (gate spec 16 S1): not modelled (before
1.14), ``COM_RC_OVERRIDE`` bit 1 with ``COM_RC_STICK_OV`` (1.14-1.17, off by default), or
``MAN_OVERRIDE_SPD`` (1.18, main: on by default)."""

UlogEra = Literal["legacy", "1.13", "1.14", "1.15", "1.16", "1.17"]
"""The uORB logging formats a ULog of the release holds, oldest first (writers/ulog_formats)."""


def _params(**values: float) -> Mapping[str, float]:
    return MappingProxyType(dict(values))


@dataclass(frozen=True, slots=True)
class Release:
    """A modelled PX4 release: its name, the versions it covers and how its offboard gate behaves.

    Field docs name the docs/gate.md section (or PX4's source at a tag) or the docs
    seed they come from.
    """

    name: str
    """The profile name (a ``PX4Profile``; ``str`` so that a test may add a record)."""
    covers: str
    """One line for ``fuzzoff profiles``: the versions and what sets the release apart."""
    minors: tuple[int, ...]
    """The PX4 ``1.x`` versions judged with this record (empty: ``main``, anything newer)."""

    # -- the offboard signal (2.1-2.3)
    loss_signal: LossSignal
    fixed_loss_s: float | None
    """Before 1.11 the signal is lost a fixed time after the newest keep-alive, and
    COM_OF_LOSS_T is an extra wait before the loss action (2.3); None: COM_OF_LOSS_T is it."""
    control_mode: ControlModeLayout
    acceleration_needs_attitude: bool
    """The acceleration flag requires an attitude estimate (1.16+), not a velocity one (2.1)."""
    attitude_flag_needs_attitude: bool
    """The attitude flag requires an attitude estimate (main's OffboardChecks, 2.1)."""
    ros2_timestamp_rewrite: bool
    """The uXRCE-DDS client rewrites a ROS 2 message's ``timestamp`` into PX4's clock, and the
    keep-alive's age comes from it (2.1.1, 1.14+)."""

    # -- the MAVLink receiver (6)
    legacy_receiver: bool
    """The legacy / 1.11 receiver (6.4 legacy, 6.5): no MAV_FWDEXTSP gate, fixed-wing
    setpoint-type bits read."""
    handles_global_int: bool
    """SET_POSITION_TARGET_GLOBAL_INT has a handler (not before v1.10, 6.3)."""
    setpoint_valid_if_any_finite: bool
    """A group counts when any component is finite (v1.13), not when not all are NaN (6.2)."""
    yaw_sets_attitude_flags: bool
    """A finite yaw (yaw rate) in SET_POSITION_TARGET_* sets the attitude (body_rate) flag (6.2)."""
    attitude_target_needs_thrust: bool
    """SET_ATTITUDE_TARGET without thrust is dropped entirely (6.4)."""

    # -- Commander's requests (4)
    accepts_disarmed_switch: bool
    """A switch to OFFBOARD while disarmed is accepted without a stream, checked at arming, and
    an armed one needs the attitude estimate and the last check pass's signal (4.1, 1.14+)."""
    checks_signal_at_arming: bool
    """Arming in OFFBOARD re-runs the checks at the request (4.2, 1.14+)."""
    arming_needs_manual_in_stick_modes: bool
    """Arming in a mode flown with the sticks (Manual, Stabilized, Acro, Altitude, Position)
    is refused without manual control: the mode's requirement, checked by ``canArm`` (4.2,
    1.14+; seen on 1.18.0-alpha1 SITL: ack 1, "Arming denied: Resolve system health failures
    first")."""
    arming_unverified: bool
    """The arming model follows old code, not checked on this release (4.2)."""
    handles_set_nav_state: bool
    """VEHICLE_CMD_SET_NAV_STATE is handled (4.1, 1.15+)."""
    unsupported_main_mode: UnsupportedModeAnswer
    never_leaves_termination: bool
    """No mode switch out of TERMINATION, armed or not (4.1, 1.16+)."""
    acks_switch_twice: bool
    """A MAVLink mode switch is acked twice: the receiver's ACCEPTED, then Commander's (4.3)."""
    altitude_cruise_mode: bool
    """DO_SET_MODE main mode 11 is ALTITUDE_CRUISE (nav_state 8, 4.1; seen on 1.17.0 SITL)."""
    guided_course_sub_mode: bool
    """AUTO sub-mode 19 is GUIDED_COURSE (16 S10, 1.18+)."""
    descend_sub_mode: bool
    """AUTO sub-mode 20 is DESCEND, shown but not selectable: a request for it is refused
    (16 S10, main after 841bb40365)."""
    stick_override: StickOverride
    """What moving sticks do to OFFBOARD (16 S1)."""
    alien_command_answer: AlienCommandAnswer
    """A COMMAND_LONG / COMMAND_INT for another system or component (and for system 0 where
    ``handles_broadcast_command`` is False): acked FAILED (up to 1.15) or ignored, no ack (1.16+).
    Never handled. SET_MODE has no component: system 0 or the vehicle's is handled everywhere."""
    handles_broadcast_command: bool
    """A COMMAND_LONG / COMMAND_INT with target_system 0 is handled like one for this vehicle."""
    old_code_unverified: bool
    """The model follows the code of those years, not checked per release: its verdicts on
    requests, controllers and disarming say unverified (legacy, 1.11)."""

    # -- the loss action (5)
    loss_failsafe: LossFailsafe
    nav_rcl_fallback: NavRclFallback
    nav_rcl_hold_no_failsafe: bool
    """NAV_RCL_ACT 7 "Hold (no failsafe)" exists (5.1)."""
    position_loss_action: bool
    """COM_POS_FS_ACT (0 Descend, 1 Terminate) decides the end of the degradation chain: 1
    skips Descend (16 S11, main)."""
    obl_rc_manual_is_stabilized: bool
    """COM_OBL_RC_ACT 2 is labelled Manual and selects Stabilized (5.1, 1.14-1.15)."""

    # -- the controllers in OFFBOARD (7, 8, 10)
    allocation_flag: bool
    """``flag_control_allocation_enabled`` is set with the rate controller (7, 1.15+)."""
    setpoint_types_control_mode: bool
    """The control flags come from ModeUtil/setpoint_types.cpp (7, main)."""
    external_mode_api: int | None
    """``LATEST_PX4_ROS2_API_VERSION``: the API version PX4's registration reply carries and
    px4-ros2-interface-lib must have been built for (16 S8: 1 from 1.15, 2 on 1.18 and main);
    None before external modes (1.14 and older)."""
    reuses_last_valid_setpoint: bool
    """mc_pos_control reuses the last valid setpoint for 200 ms before its failsafe (8, 1.16+)."""
    rover_drive_modes: bool
    """The rover modules' offboard drive modes are tabulated per flag (10, main)."""

    # -- the docs' tables (tables/)
    docs_page: DocsPage | None
    """The docs page of OffboardControlMode's table and the MAVLink rules (None: no page)."""
    docs_acceleration_needs_velocity: bool
    """The docs still ask for a velocity estimate with the acceleration flag
    (gate.md#docs-vs-code)."""
    rover_setpoints: bool
    """The rover setpoint topics and their docs table exist (1.16+)."""
    docs_say_2hz: bool
    """The release's docs ask for a proof of life at 2 Hz; the 1.18 docs give COM_OF_LOSS_T
    instead, main's say 2 Hz again (16 S12)."""

    # -- identity and evidence
    branches: tuple[str, ...]
    """ULog ``ver_sw_branch`` values other than ``release/<name>`` that name this record,
    whatever version the build reports (main reports the version of the release it is ahead
    of)."""
    reports_as: str | None
    """The record whose version this one's builds report (main: ``1.18``): a recording that
    names no branch (a tlog, a ULog without ``ver_sw_branch``) cannot tell them apart."""

    # -- message layouts
    msg_folder: str | None
    """The bundled ``px4_msgs`` folder (``sources/px4_msgs/<folder>``); None before ROS 2.
    Releases whose messages are laid out alike share one folder: two equal folders would make
    every ROS 2 recording that fits them fit two releases, and name neither."""
    ulog_era: UlogEra
    armed_error_state: bool
    """``vehicle_status.arming_state`` 3 (ARMED_ERROR) is armed too (before v1.11)."""

    # -- parameters (13)
    param_defaults: Mapping[str, float] = field(compare=False)
    """PX4's defaults of the parameters the gate reads that differ between releases."""

    @property
    def tick_based(self) -> bool:
        """The signal is judged at Commander's 10 Hz check pass (2.1, 1.14+)."""
        return self.loss_signal == "tick"

    @property
    def control_mode_flags(self) -> bool:
        """OffboardControlMode has boolean flags (1.13+): before it any keep-alive counts,
        whatever it says, and there is no ROS 2 interface."""
        return self.control_mode != "ignore_fields"

    @property
    def consults_manual_control_on_loss(self) -> bool:
        """Whether manual control being present changes the loss action (not 1.14-1.16)."""
        return self.loss_failsafe != "framework" or self.nav_rcl_fallback != "none"


LEGACY = Release(
    name="legacy",
    covers="v1.5-v1.10: ignore_* control mode, fixed 500 ms loss timeout",
    minors=(5, 6, 7, 8, 9, 10),
    loss_signal="fixed",
    fixed_loss_s=0.5,
    control_mode="ignore_fields",
    acceleration_needs_attitude=False,
    attitude_flag_needs_attitude=False,
    ros2_timestamp_rewrite=False,
    legacy_receiver=True,
    handles_global_int=False,
    setpoint_valid_if_any_finite=True,
    yaw_sets_attitude_flags=False,
    attitude_target_needs_thrust=False,
    accepts_disarmed_switch=False,
    checks_signal_at_arming=False,
    arming_needs_manual_in_stick_modes=False,
    arming_unverified=True,
    handles_set_nav_state=False,
    unsupported_main_mode="rejected_unverified",
    never_leaves_termination=False,
    acks_switch_twice=False,
    altitude_cruise_mode=False,
    guided_course_sub_mode=False,
    descend_sub_mode=False,
    stick_override="none",
    alien_command_answer="ack_failed",
    handles_broadcast_command=False,
    old_code_unverified=True,
    loss_failsafe="state_machine_legacy",
    nav_rcl_fallback="none",
    nav_rcl_hold_no_failsafe=False,
    position_loss_action=False,
    obl_rc_manual_is_stabilized=False,
    allocation_flag=False,
    setpoint_types_control_mode=False,
    external_mode_api=None,
    reuses_last_valid_setpoint=False,
    rover_drive_modes=False,
    docs_page=None,
    docs_acceleration_needs_velocity=False,
    rover_setpoints=False,
    docs_say_2hz=True,
    branches=(),
    reports_as=None,
    msg_folder=None,
    ulog_era="legacy",
    armed_error_state=True,
    param_defaults=_params(COM_OF_LOSS_T=0.0, COM_DISARM_PRFLT=0.0, COM_OBL_ACT=0.0),
)

V1_11 = replace(
    LEGACY,
    name="1.11",
    covers="v1.11: legacy receiver, timestamp-age gate with COM_OF_LOSS_T (0.5 s)",
    minors=(11,),
    loss_signal="age",
    fixed_loss_s=None,
    handles_global_int=True,
    arming_unverified=False,
    armed_error_state=False,
    loss_failsafe="state_machine",
    param_defaults=_params(COM_OF_LOSS_T=0.5, COM_DISARM_PRFLT=10.0, COM_OBL_ACT=0.0),
)

V1_13 = replace(
    V1_11,
    name="1.13",
    covers="v1.12-v1.13: boolean OffboardControlMode, hysteresis gate, COM_OBL_ACT/COM_OBL_RC_ACT",
    minors=(12, 13),
    loss_signal="hysteresis",
    control_mode="actuator",
    legacy_receiver=False,
    old_code_unverified=False,
    docs_page="002",
    docs_acceleration_needs_velocity=True,
    msg_folder="1.13",
    ulog_era="1.13",
    param_defaults=_params(COM_OF_LOSS_T=1.0, COM_DISARM_PRFLT=10.0, COM_OBL_ACT=0.0),
)

V1_14 = replace(
    V1_13,
    name="1.14",
    covers="v1.14: new Commander, failsafe framework, disarmed switch always accepted",
    minors=(14,),
    loss_signal="tick",
    ros2_timestamp_rewrite=True,
    setpoint_valid_if_any_finite=False,
    accepts_disarmed_switch=True,
    checks_signal_at_arming=True,
    arming_needs_manual_in_stick_modes=True,
    unsupported_main_mode="acked_no_change",
    loss_failsafe="framework",
    obl_rc_manual_is_stabilized=True,
    stick_override="com_rc_override",
    msg_folder="1.14",
    ulog_era="1.14",
    param_defaults=_params(  # COM_OBL_ACT removed
        COM_OF_LOSS_T=1.0, COM_DISARM_PRFLT=10.0, COM_RC_OVERRIDE=1.0, COM_RC_STICK_OV=30.0
    ),
)

V1_15 = replace(
    V1_14,
    name="1.15",
    covers="v1.15: thrust_and_torque/direct_actuator flags, SET_NAV_STATE",
    minors=(15,),
    control_mode="thrust_and_torque",
    handles_set_nav_state=True,
    allocation_flag=True,
    external_mode_api=1,
    docs_page="000",
    msg_folder="1.15",
    ulog_era="1.15",
)

V1_16 = replace(
    V1_15,
    name="1.16",
    covers=(
        "v1.16: acceleration needs attitude, 200 ms last-valid fallback, two mode acks "
        "(one on branch builds after 2026-05-19)"
    ),
    minors=(16,),
    acceleration_needs_attitude=True,
    never_leaves_termination=True,
    acks_switch_twice=True,
    alien_command_answer="ignored",
    obl_rc_manual_is_stabilized=False,
    reuses_last_valid_setpoint=True,
    docs_acceleration_needs_velocity=False,
    rover_setpoints=True,
    msg_folder="1.16",
    ulog_era="1.16",
)

V1_17 = replace(
    V1_16,
    name="1.17",
    covers=(
        "v1.17: offboard loss without RC uses NAV_RCL_ACT, ALTITUDE_CRUISE, two mode acks "
        "(one on branch builds after 2026-05-19: the recording's acks decide)"
    ),
    minors=(17,),
    nav_rcl_fallback="before_degrade",
    altitude_cruise_mode=True,
    msg_folder="1.17",
    ulog_era="1.17",
)

V1_18 = replace(
    V1_17,
    name="1.18",
    covers=(
        "v1.18 (release/1.18 to 83c4f4e580, beyond beta1): sticks end OFFBOARD "
        "(MAN_OVERRIDE_SPD), thrust required for SET_ATTITUDE_TARGET, one ack, GUIDED_COURSE"
    ),
    minors=(18,),
    attitude_flag_needs_attitude=True,
    yaw_sets_attitude_flags=True,
    attitude_target_needs_thrust=True,
    unsupported_main_mode="rejected",
    acks_switch_twice=False,
    handles_broadcast_command=True,
    nav_rcl_fallback="after_degrade",
    nav_rcl_hold_no_failsafe=True,
    setpoint_types_control_mode=True,
    external_mode_api=2,
    rover_drive_modes=True,
    guided_course_sub_mode=True,
    stick_override="man_override_spd",
    docs_say_2hz=False,
    # MAN_OVERRIDE_SPD replaces COM_RC_OVERRIDE and COM_RC_STICK_OV (16 S1)
    param_defaults=_params(COM_OF_LOSS_T=1.0, COM_DISARM_PRFLT=10.0, MAN_OVERRIDE_SPD=1.0),
    msg_folder="main",  # release/1.18's px4_msgs: main's layouts (one folder, see msg_folder)
)

MAIN = replace(
    V1_18,
    name="main",
    covers=(
        "main (PX4's development branch, at bb59c637cd of 2026-08-13): as 1.18, plus "
        "COM_POS_FS_ACT in the loss chain, DESCEND shown as AUTO sub-mode 20; reports 1.18.0 beta"
    ),
    minors=(),
    descend_sub_mode=True,
    position_loss_action=True,
    docs_say_2hz=True,
    branches=("main", "master"),
    reports_as="1.18",
    param_defaults=_params(
        COM_OF_LOSS_T=1.0, COM_DISARM_PRFLT=10.0, MAN_OVERRIDE_SPD=1.0, COM_POS_FS_ACT=0.0
    ),
)

SEEN_RUNNING: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {
        "1.14": ("1.14.4",),
        "1.15": ("1.15.4",),
        "1.16": ("1.16.2", "1.16.2-ros2"),
        "1.17": ("1.17.0", "1.17.0-ros2-rover"),
        # alpha1 has none of 1.18's gate changes (gate spec 16): judged as 1.18 where it agrees
        "1.18": ("1.18.0-beta1-head", "1.18.0-alpha1"),
        "main": ("main-2026-08-13",),
    }
)
"""Profile name -> the PX4 SITL builds (``../shared/px4-sitl``) the record was checked against
live; a record not listed is modelled from the code only. Evidence, not behaviour: a new
record starts unlisted."""

RELEASES: tuple[Release, ...] = (LEGACY, V1_11, V1_13, V1_14, V1_15, V1_16, V1_17, V1_18, MAIN)
"""Oldest to newest, ``main`` last. Read it at call time (a test may extend it)."""


class UnknownRelease(KeyError):
    """No record has this name."""


def names() -> tuple[PX4Profile, ...]:
    """The profile names, oldest first."""
    return tuple(r.name for r in RELEASES)  # type: ignore[misc]  # a record's name is one


_index: tuple[tuple[Release, ...], dict[str, Release]] = ((), {})
"""``RELEASES`` by name, made again when ``RELEASES`` is another tuple."""


def get(name: str) -> Release:
    """The record named ``name`` (a profile name such as ``1.15`` or ``main``)."""
    global _index
    table, by_name = _index
    if table is not RELEASES:
        by_name = {r.name: r for r in RELEASES}
        _index = (RELEASES, by_name)
    try:
        return by_name[name]
    except KeyError:
        raise UnknownRelease(name) from None


def for_version(major: int, minor: int) -> Release:
    """The record that judges PX4 ``major.minor``: the oldest below every listed version, the
    newest (``main``) above them."""
    if major == 1:
        for release in RELEASES:
            if minor in release.minors:
                return release
        listed = [m for r in RELEASES for m in r.minors]
        if listed and minor < min(listed):
            return RELEASES[0]
    return RELEASES[0] if major < 1 else RELEASES[-1]


_VERSION = re.compile(r"^v?(\d+)\.(\d+)(?:\.(\d+))?")
"""A release as PX4 names it: ``1.15.4``, ``v1.17.0-beta1``, ``1.14``."""


def version_of(text: str) -> tuple[int, int] | None:
    """``(major, minor)`` of a release name (``v1.17.0-beta1`` -> ``(1, 17)``); None for text
    that names no release."""
    found = _VERSION.match(text.strip())
    return None if found is None else (int(found.group(1)), int(found.group(2)))


def named(text: str) -> Release | None:
    """The record a profile name (``main``) or a release (``1.15.4``) stands for: the one
    place a name is parsed (``--px4``, a recording's version, a reproducer's profile). None
    when the text is neither."""
    name = text.strip()
    if name in names():
        return get(name)
    version = version_of(name)
    return None if version is None else for_version(*version)


def for_branch(branch: str | None) -> Release | None:
    """The record a ULog's ``ver_sw_branch`` names (``main``, ``release/1.18``), None for a
    branch no record names (a fork's, a tag's build: the version decides)."""
    if not branch:
        return None
    for release in RELEASES:
        if branch in release.branches or branch == f"release/{release.name}":
            return release
    return None


def reported_alike(release: Release) -> tuple[Release, ...]:
    """The other records whose builds report the same version as ``release`` (1.18 and main)."""
    return tuple(
        r
        for r in RELEASES
        if r is not release and (r.reports_as == release.name or r.name == release.reports_as)
    )


def newest_listed() -> tuple[int, int]:
    """The newest ``1.x`` a record names (``1.18``): releases past it are not modelled."""
    return 1, max(m for r in RELEASES for m in r.minors)


def oldest_listed() -> tuple[int, int]:
    """The oldest ``1.x`` a record names (``1.5``)."""
    return 1, min(m for r in RELEASES for m in r.minors)
