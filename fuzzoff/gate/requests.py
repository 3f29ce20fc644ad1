"""Mode-switch, arming and disarming requests: accepted or rejected, and why (gate.md#requests,
#seen-on-px4).

``mode_request`` turns a command into the nav_state it asks for (or why the release has none);
``switch_decision``, ``arm_decision`` and ``disarm_decision`` return ``Decision`` (accepted,
reason, spec, ack result).
"""

from __future__ import annotations

from fuzzoff.events import (
    MAV_CMD_DO_SET_MODE,
    NAV_STATE_OFFBOARD,
    VEHICLE_CMD_SET_NAV_STATE,
    Command,
    nearest,
    whole,
)
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import custom_mode_to_nav_state, nav_state_name
from fuzzoff.releases import Release

TERMINATION = 13
FORCE_ARM_MAGIC = 21196
ACCEPTED = 0
TEMPORARILY_REJECTED = 1
DENIED = 2
UNSUPPORTED = 3
FAILED = 4
NO_ATTITUDE = "no attitude or angular-velocity estimate (OFFBOARD mode requirement, D11)"
STICK_MODES = frozenset({0, 1, 2, 10, 15})
"""Nav states flown with the sticks: Manual, Altitude, Position, Acro, Stabilized."""


@dataclass(frozen=True, slots=True)
class Decision:
    accepted: bool
    spec: str
    reason: str | None = None
    result: int = ACCEPTED
    changes: bool = True
    """False for a request acked ACCEPTED that changes nothing (unsupported main mode, 4.1)."""
    unverified: bool = False


MAIN_AUTO = 4
MAIN_ALTITUDE_CRUISE = 11
NAV_AUTO_MISSION = 3
NAV_ALTITUDE_CRUISE = 8
SUB_GUIDED_COURSE = 19
SUB_DESCEND = 20


def decode_mode(cmd: Command, release: Release | None = None) -> int | None:
    """The nav_state a mode command asks for (None: not a mode, or one ``release`` lacks)."""
    return mode_request(cmd, release)[0]


def mode_request(cmd: Command, release: Release | None = None) -> tuple[int | None, str | None]:
    """(the nav_state a mode command asks for, None), or (None, why PX4 has no such mode) as
    Commander reads DO_SET_MODE (4.1, seen on 1.16.2-main SITL): AUTO with sub-mode 0 is Mission,
    an AUTO sub-mode Commander does not know is refused, ALTITUDE_CRUISE (main 11) exists from
    1.17, GUIDED_COURSE (AUTO 19) from 1.18, and main shows DESCEND as AUTO 20 but refuses a
    request for it (16 S10). Without ``release`` every mode fuzzoff knows counts."""
    if cmd.command == VEHICLE_CMD_SET_NAV_STATE:
        return whole(cmd.params[0]), None
    if cmd.command != MAV_CMD_DO_SET_MODE:
        return None, None
    base, main, sub = (whole(p) for p in cmd.params[:3])
    if base is None or base & 1 == 0:
        return None, "base mode without the custom-mode flag"
    if main is None or sub is None:
        return None, "main or sub mode not a whole number"
    main, sub = main & 0xFF, sub & 0xFF
    if main == MAIN_AUTO and sub == 0:
        return NAV_AUTO_MISSION, None
    if main == MAIN_ALTITUDE_CRUISE:
        if release is None or release.altitude_cruise_mode:
            return NAV_ALTITUDE_CRUISE, None
        return None, f"main mode {main} (ALTITUDE_CRUISE, PX4 1.17 and later)"
    course = main == MAIN_AUTO and sub == SUB_GUIDED_COURSE
    if course and release is not None and not release.guided_course_sub_mode:
        return None, f"AUTO sub-mode {sub} (GUIDED_COURSE, PX4 1.18 and later)"
    if main == MAIN_AUTO and sub == SUB_DESCEND and release is not None:
        if release.descend_sub_mode:  # shown as DESCEND, not selectable (16 S10)
            return None, f"AUTO sub-mode {sub} (DESCEND: shown, not selectable on main)"
        return None, f"AUTO sub-mode {sub}"
    nav = custom_mode_to_nav_state(main << 16 | sub << 24)
    if nav is not None:
        return nav, None
    if main == MAIN_AUTO:
        return None, f"AUTO sub-mode {sub}"
    return None, f"main mode {main}"


def switch_decision(
    release: Release,
    cmd: Command,
    target: int | None,
    armed: bool,
    signal_ok: bool,
    nav_state: int | None,
    attitude_ok: bool = True,
) -> Decision:
    """A mode switch (4.1). ``signal_ok`` is the last check pass's verdict (1.14+) or the
    current flag (older)."""
    if cmd.command == VEHICLE_CMD_SET_NAV_STATE and not release.handles_set_nav_state:
        return Decision(False, "4.1", "SET_NAV_STATE is not handled before 1.15", UNSUPPORTED)
    if target is None:
        return unknown_mode_decision(release, mode_request(cmd, release)[1])
    if release.never_leaves_termination and nav_state == TERMINATION:  # armed or not
        return Decision(False, "4.1", "never out of TERMINATION", TEMPORARILY_REJECTED)
    if target != NAV_STATE_OFFBOARD:
        # Other modes' requirements are not modelled: assumed accepted.
        return Decision(True, "4.1", None, unverified=False)
    if release.accepts_disarmed_switch:
        if not armed:
            return Decision(True, "4.1", None)
        if not attitude_ok:
            return Decision(False, "4.1", NO_ATTITUDE, TEMPORARILY_REJECTED)
        if signal_ok:
            return Decision(True, "4.1", None)
        return Decision(False, "4.1", "no offboard signal", TEMPORARILY_REJECTED)
    if signal_ok:
        return Decision(True, "4.1", None)
    return Decision(False, "4.1", "no offboard signal", TEMPORARILY_REJECTED)


def unknown_mode_decision(release: Release, problem: str | None) -> Decision:
    """Commander's answer to DO_SET_MODE for a mode this release does not have (4.1): an
    unknown AUTO sub-mode is refused on every release; another unknown main mode is acked
    ACCEPTED with no change (1.14-1.17) or refused (1.18+)."""
    what = f"no such mode: {problem}" if problem else "no such mode"
    if problem is not None and problem.startswith("AUTO sub-mode"):
        return Decision(False, "4.1", what, TEMPORARILY_REJECTED)
    if release.unsupported_main_mode == "rejected":
        return Decision(False, "4.1", what, TEMPORARILY_REJECTED)
    if release.unsupported_main_mode == "acked_no_change":
        return Decision(True, "4.1", f"{what}: acked, no mode change", changes=False)
    return Decision(False, "4.1", what, TEMPORARILY_REJECTED, unverified=True)


def arm_decision(
    release: Release,
    cmd: Command,
    intention: int | None,
    signal_now: bool,
    why: str | None,
    attitude_ok: bool = True,
    armed: bool = False,
    manual_control: bool = True,
) -> Decision:
    """Arming (4.2). ``signal_now`` is the condition evaluated at the request (1.14+ re-runs the
    checks); ``why`` the reason it fails. Arming an armed vehicle changes nothing and is acked
    ACCEPTED (Commander's ``arm()`` returns "not changed"; seen on 1.15.4 and 1.18.0-alpha1 SITL
    after a refused disarm in flight). Arming in a stick mode needs ``manual_control`` (1.14+):
    a generated stream that switched to Position without a joystick was refused on 1.18 SITL."""
    if armed:
        return Decision(
            True,
            "4.2",
            "already armed: acked ACCEPTED, no change",
            changes=False,
            unverified=release.old_code_unverified,
        )
    if intention != NAV_STATE_OFFBOARD:
        stick = intention in STICK_MODES and not manual_control
        if stick and release.arming_needs_manual_in_stick_modes:
            mode = nav_state_name(intention)
            why = f"no manual control, which {mode} needs (mode requirement)"
            return Decision(False, "4.2", why, TEMPORARILY_REJECTED)
        return Decision(True, "4.2", None)
    if not release.checks_signal_at_arming:
        return Decision(True, "4.2", None, unverified=release.arming_unverified)
    forced = nearest(cmd.params[1]) == FORCE_ARM_MAGIC
    if forced and cmd.from_external is False:
        return Decision(True, "4.2", "forced arming from an internal source: checks skipped")
    if not attitude_ok:
        return Decision(False, "4.2", NO_ATTITUDE, TEMPORARILY_REJECTED)
    if signal_now:
        return Decision(True, "4.2", None)
    return Decision(False, "4.2", why or "no offboard signal", TEMPORARILY_REJECTED)


def disarm_decision(
    release: Release, cmd: Command, armed: bool, landed: bool, why: str, ground_vehicle: bool
) -> Decision:
    """Disarming (13a): refused unless forced (param2 21196, from any source), landed
    (``landed``/``maybe_landed``) or a ground vehicle. Seen on 1.15.4 and 1.18.0-alpha1 SITL:
    ack 1, "Disarming denied: not landed". 1.12+ ack it TEMPORARILY_REJECTED; older releases
    DENIED (from the code of those years, unverified per release). ``why`` says where the landed
    state comes from."""
    if not armed:
        return Decision(True, "13a", "already disarmed: acked ACCEPTED, no change", changes=False)
    if nearest(cmd.params[1]) == FORCE_ARM_MAGIC:
        return Decision(True, "13a", "forced disarm (param2 21196): the land check is skipped")
    if ground_vehicle:
        return Decision(True, "13a", "a ground vehicle disarms anywhere")
    if landed:
        return Decision(True, "13a", why)
    old = release.old_code_unverified
    return Decision(
        False,
        "13a",
        f"Disarming denied: not landed ({why})",
        DENIED if old else TEMPORARILY_REJECTED,
        unverified=old,
    )
