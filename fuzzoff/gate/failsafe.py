"""What the vehicle does when the offboard signal is lost, per profile (gate.md#loss).

``loss_action(release, vehicle, params, est, stage)`` gives the action the failsafe selects at that
moment. Mode requirements used for the degradation chains are fuzzoff's approximation of PX4's
mode requirements (gate.md#loss gives the chains, not every requirement): results that depend on
them are marked ``unverified``.
"""

from __future__ import annotations

from dataclasses import replace

from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.params import RC_PRESENT
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name
from fuzzoff.releases import Release

MANUAL, ALTCTL, POSCTL, LOITER, RTL, LANDGPSFAIL, DESCEND, TERMINATION = 0, 1, 2, 4, 5, 9, 12, 13
OFFBOARD, STAB, LAND = 14, 15, 18


@dataclass(frozen=True, slots=True)
class LossAction:
    """``nav_state`` None = no mode change (Disarm, or no failsafe at all)."""

    action: str
    nav_state: int | None
    spec: str
    note: str = ""
    disarm: bool = False
    unverified: bool = False
    degraded_from: str | None = None
    """The configured action, when its mode could not run and the chain picked another."""
    stick_mode_without_rc: bool = False
    """A stick mode (Position/Altitude/Stabilized/Manual) is selected with no manual control."""
    replaced_from: str | None = None
    """1.17+: the stick mode that was selected, replaced by the NAV_RCL_ACT action because the
    vehicle has no manual control."""

    @property
    def none(self) -> bool:
        return self.nav_state is None and not self.disarm


NO_FAILSAFE = LossAction("NONE", None, "5.1", "no failsafe: the vehicle stays in OFFBOARD")


def _name(nav: int) -> str:
    return nav_state_name(nav)


def can_run(nav: int, est: Estimates, vehicle: str) -> bool:
    """fuzzoff's approximation of PX4's mode requirements (unverified in detail)."""
    if nav == POSCTL:
        if vehicle == "fw":
            return est.global_position
        return est.local_position and est.local_velocity
    if nav == ALTCTL:
        return est.local_altitude
    if nav in (STAB, DESCEND, MANUAL):
        return est.attitude
    if nav == LOITER:
        return est.global_position
    if nav == RTL:
        return est.global_position and est.home_position
    if nav == LAND:
        return est.local_position
    return True


# Framework degradation order with fall-through (5.1, getSelectedAction).
_CHAIN_14 = (POSCTL, ALTCTL, STAB, LOITER, RTL, LAND, DESCEND, TERMINATION)
_STICK = (POSCTL, ALTCTL, STAB)
_OBL_RC_14 = {0: POSCTL, 1: ALTCTL, 2: STAB, 3: RTL, 4: LAND, 5: LOITER, 6: TERMINATION}
_NAV_RCL = {1: LOITER, 2: RTL, 3: LAND, 5: TERMINATION}


_CHAIN_NO_DESCEND = tuple(nav for nav in _CHAIN_14 if nav != DESCEND)


def _chain(release: Release, params: dict[str, float]) -> tuple[int, ...]:
    """The 1.14+ degradation chain; main's COM_POS_FS_ACT 1 (Terminate) skips Descend when
    the position is lost (gate spec 16 S11)."""
    if release.position_loss_action and params.get("COM_POS_FS_ACT", 0.0) == 1.0:
        return _CHAIN_NO_DESCEND
    return _CHAIN_14


def _degrade(nav: int, est: Estimates, vehicle: str, chain: tuple[int, ...]) -> int:
    start = chain.index(nav) if nav in chain else 0
    for candidate in chain[start:]:
        if can_run(candidate, est, vehicle):
            return candidate
    return TERMINATION


def rc_present(params: dict[str, float], est: Estimates) -> bool:
    """Manual control as recorded, else the ``FUZZOFF_RC_PRESENT`` assumption."""
    if est.rc_recorded:
        return est.rc_present
    return bool(params.get(RC_PRESENT, 1.0))


def _finish(
    chosen: int,
    final: int,
    spec: str,
    unverified: bool,
    note: str,
    rc: bool,
) -> LossAction:
    degraded = _name(chosen) if final != chosen else None
    if degraded is not None:
        note = (note + "; " if note else "") + f"{degraded} cannot run, degraded to {_name(final)}"
    return LossAction(
        action=_name(final),
        nav_state=final,
        spec=spec,
        note=note,
        unverified=unverified or degraded is not None,
        degraded_from=degraded,
        stick_mode_without_rc=final in (POSCTL, ALTCTL, STAB, MANUAL) and not rc,
    )


def _nav_rcl_action(value: int, release: Release) -> tuple[int | None, bool, str]:
    """NAV_RCL_ACT as the replacement action of 1.17+ (5.1): (nav, unverified, label)."""
    if value == 0:
        return None, True, "NAV_RCL_ACT 0 (Disabled): no failsafe"
    if value == 6:
        return None, False, "NAV_RCL_ACT 6 (Disarm)"
    if value == 7 and release.nav_rcl_hold_no_failsafe:
        return LOITER, True, "NAV_RCL_ACT 7 (Hold, no failsafe)"
    nav = _NAV_RCL.get(value)
    if nav is None:
        return RTL, True, f"NAV_RCL_ACT {value} (not a documented value; Return assumed)"
    return nav, False, f"NAV_RCL_ACT {value}"


def _framework(
    release: Release, vehicle: str, params: dict[str, float], est: Estimates
) -> LossAction:
    """1.14 - main (5.1)."""
    raw = params.get("COM_OBL_RC_ACT", 0.0)
    value = int(raw) if raw == int(raw) else -99
    rc = rc_present(params, est)
    note = f"COM_OBL_RC_ACT {raw:g}"
    if value == 7:
        return LossAction("DISARM", None, "5.1", note, disarm=True)
    chosen = _OBL_RC_14.get(value, POSCTL)
    if value not in _OBL_RC_14:
        note += " (out of range: treated as 0, Position)"
    if value == 2 and release.obl_rc_manual_is_stabilized:
        note += " (labelled Manual, selects Stabilized)"
    chain = _chain(release, params)
    if chain is _CHAIN_NO_DESCEND:
        note += "; COM_POS_FS_ACT 1: Terminate instead of Descend"
    if release.nav_rcl_fallback == "none":
        if chosen == POSCTL and params.get("COM_POSCTL_NAVL", 0.0) == 1.0:
            final = _degrade(POSCTL, est, vehicle, (POSCTL, LAND, DESCEND, TERMINATION))
        else:
            final = _degrade(chosen, est, vehicle, chain)
        return _finish(chosen, final, "5.1", False, note, rc)
    # 1.17: replace a stick mode by NAV_RCL_ACT first; 1.18 and main: after the stick chain.
    if not est.rc_recorded:
        note += f"; manual control assumed {'present' if rc else 'absent'} ({RC_PRESENT})"
    if release.nav_rcl_fallback == "before_degrade" and chosen in _STICK and not rc:
        return _replace(release, vehicle, params, est, chosen, note, rc)
    final = _degrade(chosen, est, vehicle, chain)
    if release.nav_rcl_fallback == "after_degrade" and final in _STICK and not rc:
        return _replace(release, vehicle, params, est, final, note, rc)
    return _finish(chosen, final, "5.1", False, note, rc)


def _replace(
    release: Release,
    vehicle: str,
    params: dict[str, float],
    est: Estimates,
    chosen: int,
    note: str,
    rc: bool,
) -> LossAction:
    nav, unverified, label = _nav_rcl_action(int(params.get("NAV_RCL_ACT", 2.0)), release)
    stick = _name(chosen)
    note += f"; no manual control: {stick} replaced by {label}"
    if nav is None:
        if "Disarm" in label:
            return LossAction("DISARM", None, "5.1", note, disarm=True, replaced_from=stick)
        return LossAction("NONE", None, "5.1", note, unverified=unverified, replaced_from=stick)
    final = _degrade(nav, est, vehicle, _chain(release, params))
    return replace(_finish(nav, final, "5.1", unverified, note, rc), replaced_from=stick)


# v1.13 (5.2)
_OBL_13 = {-1: None, 0: LAND, 1: LOITER, 2: RTL, 3: TERMINATION, 4: -4}
_OBL_RC_13 = {
    -1: None,
    0: POSCTL,
    1: ALTCTL,
    2: MANUAL,
    3: RTL,
    4: LAND,
    5: LOITER,
    6: TERMINATION,
    7: -4,
}
_LOCKDOWN = -4


def _chain_13(nav: int, est: Estimates, vehicle: str) -> int:
    """The fallbacks of 5.2: Position -> Altitude -> Manual; Return -> Hold -> Land ->
    Descend -> Termination."""
    if nav == POSCTL:
        position = est.global_position if vehicle == "fw" else est.local_position
        if position:
            return POSCTL
        return ALTCTL if est.local_altitude else MANUAL
    if nav == ALTCTL:
        return ALTCTL if est.local_altitude else MANUAL
    if nav == RTL:
        if est.global_position and est.home_position:
            return RTL
        nav = LOITER
    if nav == LOITER:
        if est.global_position:
            return LOITER
        nav = LAND
    if nav == LAND:
        if est.local_position:
            return LAND
        return DESCEND if est.local_altitude else TERMINATION
    return nav


def _v113(release: Release, vehicle: str, params: dict[str, float], est: Estimates) -> LossAction:
    rc = rc_present(params, est)
    exception = int(params.get("COM_RCL_EXCEPT", 0.0)) & 4 != 0
    unverified = release.old_code_unverified
    spec = "5.2"
    if rc and not exception:
        name, table = "COM_OBL_RC_ACT", _OBL_RC_13
    else:
        name, table = "COM_OBL_ACT", _OBL_13
    raw = params.get(name, 0.0)
    value = int(raw) if raw == int(raw) else -99
    why = "RC present" if rc and not exception else "no RC" if not rc else "COM_RCL_EXCEPT bit 2"
    note = f"{name} {raw:g} ({why})"
    if value not in table:
        note += " (out of range: treated as the default 0)"
        value = 0
        unverified = True
    chosen = table[value]
    if chosen is None:
        return LossAction(
            "NONE", None, spec, note + ": Disabled, stays in OFFBOARD", unverified=unverified
        )
    if chosen == _LOCKDOWN:
        return LossAction(
            "LOCKDOWN", TERMINATION, spec, note + ": Lockdown (motors off)", unverified=True
        )
    final = _chain_13(chosen, est, vehicle)
    return _finish(chosen, final, spec, unverified, note, rc)


# legacy (5.3)
_LEGACY_RC = {0: POSCTL, 1: ALTCTL, 2: MANUAL, 3: RTL, 4: LAND, 5: LOITER}
_LEGACY_NO_RC = {0: LAND, 1: LOITER, 2: RTL}


def _legacy_stage1(vehicle: str, est: Estimates, rc: bool) -> int:
    if rc:
        if est.global_position:
            return POSCTL
        return ALTCTL if est.local_altitude else TERMINATION
    if est.global_position:
        return LOITER
    if est.local_altitude:
        return LANDGPSFAIL if vehicle == "fw" else DESCEND
    return TERMINATION


def _legacy_needs(nav: int, est: Estimates) -> bool:
    if nav in (POSCTL, LAND, LOITER):
        return est.global_position
    if nav == ALTCTL:
        return est.local_altitude
    if nav == RTL:
        return est.global_position and est.home_position
    return True


def _legacy(vehicle: str, params: dict[str, float], est: Estimates, stage: int) -> LossAction:
    rc = rc_present(params, est)
    stage1 = _legacy_stage1(vehicle, est, rc)
    if stage == 1:
        where = "RC present" if rc else "no RC"
        return _finish(stage1, stage1, "5.3", False, f"legacy stage 1 ({where})", rc)
    name, table = ("COM_OBL_RC_ACT", _LEGACY_RC) if rc else ("COM_OBL_ACT", _LEGACY_NO_RC)
    raw = params.get(name, 0.0)
    value = int(raw) if raw == int(raw) else -99
    note = f"legacy loss timeout: {name} {raw:g}"
    if value not in table:
        return _finish(stage1, stage1, "5.3", False, note + " (out of range: stage 1 kept)", rc)
    chosen = table[value]
    if _legacy_needs(chosen, est):
        return _finish(chosen, chosen, "5.3", False, note, rc)
    final = (LANDGPSFAIL if vehicle == "fw" else DESCEND) if est.local_altitude else TERMINATION
    return _finish(chosen, final, "5.3", False, note, rc)


READ_PARAMS: tuple[str, ...] = (
    "COM_OBL_ACT",
    "COM_OBL_RC_ACT",
    "COM_POS_FS_ACT",
    "COM_POSCTL_NAVL",
    "COM_RCL_EXCEPT",
    "NAV_RCL_ACT",
    RC_PRESENT,
)
"""Every parameter the loss action reads (``tests/test_gate_failsafe_memo.py`` holds the
functions above to this list): the memo's key."""

_MEMO_LIMIT = 256
_memo: dict[tuple[object, ...], tuple[Release, LossAction]] = {}


def loss_action(
    release: Release, vehicle: str, params: dict[str, float], est: Estimates, stage: int = 2
) -> LossAction:
    """The action on offboard loss now. ``stage`` is legacy's: 1 = lost, 2 = loss timeout.

    Remembered by everything it reads (a check asks at every status and flags message while
    offboard, issue 31); the answer is frozen, so sharing it is safe."""
    key = (
        id(release),
        vehicle,
        stage,
        est.bits,
        est.rc_recorded,
        tuple(map(params.get, READ_PARAMS)),
    )
    found = _memo.get(key)
    if found is not None and found[0] is release:
        return found[1]
    action = _loss_action(release, vehicle, params, est, stage)
    if len(_memo) >= _MEMO_LIMIT:
        _memo.clear()
    _memo[key] = (release, action)
    return action


def _loss_action(
    release: Release, vehicle: str, params: dict[str, float], est: Estimates, stage: int
) -> LossAction:
    if release.loss_failsafe == "state_machine_legacy":
        return _legacy(vehicle, params, est, stage)
    if release.loss_failsafe == "state_machine":
        return _v113(release, vehicle, params, est)
    return _framework(release, vehicle, params, est)
