"""Loss action per profile for every COM_OBL_RC_ACT value (gate spec 5.1, 5.2, 5.3).

Expected values are the spec's tables: 5.1 (1.14 - main, framework actions), 5.2 (1.13:
RC-dependent COM_OBL_RC_ACT / COM_OBL_ACT, -1..7), 5.3 (legacy, two stages, v1.7 range 0-5).
"""

from __future__ import annotations

import pytest

from tests.gate.streams import (
    ALTCTL,
    LAND,
    LOITER,
    MANUAL,
    OFFBOARD,
    POSCTL,
    RTL,
    STAB,
    TERMINATION,
    TICK,
    flags,
    in_offboard,
    of,
    run,
    stream,
)

OUT_OF_RANGE = 9.0

# 5.1: value -> (action, nav_state); 7 disarms; anything else is the switch default (0).
FRAMEWORK = {
    0: ("POSCTL", POSCTL),
    1: ("ALTCTL", ALTCTL),
    2: ("STAB", STAB),
    3: ("AUTO_RTL", RTL),
    4: ("AUTO_LAND", LAND),
    5: ("AUTO_LOITER", LOITER),
    6: ("TERMINATION", TERMINATION),
    7: ("DISARM", None),
    OUT_OF_RANGE: ("POSCTL", POSCTL),
}

# 5.2 with RC present: -1 Disabled ... 7 Lockdown.
V113_RC = {
    -1: ("NONE", None),
    0: ("POSCTL", POSCTL),
    1: ("ALTCTL", ALTCTL),
    2: ("MANUAL", MANUAL),
    3: ("AUTO_RTL", RTL),
    4: ("AUTO_LAND", LAND),
    5: ("AUTO_LOITER", LOITER),
    6: ("TERMINATION", TERMINATION),
    7: ("LOCKDOWN", None),  # nav_state of Lockdown not in the spec
}

# 5.3 loss-timeout stage with RC: v1.7 range 0-5, else the stage-1 behaviour (POSCTL with a
# global position).
LEGACY_RC = {
    0: ("POSCTL", POSCTL),
    1: ("ALTCTL", ALTCTL),
    2: ("MANUAL", MANUAL),
    3: ("AUTO_RTL", RTL),
    4: ("AUTO_LAND", LAND),
    5: ("AUTO_LOITER", LOITER),
    6: ("POSCTL", POSCTL),
    7: ("POSCTL", POSCTL),
    OUT_OF_RANGE: ("POSCTL", POSCTL),
}


def _lose(px4: str, *, extra: list | None = None, **params: float) -> list:  # type: ignore[type-arg]
    events = [in_offboard(), *stream(0.0, 1.0), *(extra or [])]
    return run(px4, events, params=params, t_end=4.0)


@pytest.mark.parametrize("px4", TICK)
@pytest.mark.parametrize("value", list(FRAMEWORK))
def test_5_1_loss_action_per_value(px4: str, value: float) -> None:
    """5.1: COM_OBL_RC_ACT -> framework action; RC present (1.17+ only consults RC)."""
    trs = _lose(px4, COM_OBL_RC_ACT=float(value))
    action, nav = FRAMEWORK[value]
    (failsafe,) = of("failsafe", trs)
    assert failsafe.action == action
    assert 2.0 <= failsafe.t <= 2.0 + 0.11 + 1e-9  # one COM_OF_LOSS_T, no extra delay
    if nav is not None:
        assert failsafe.nav_state == nav
    else:
        assert of("disarmed", trs), "7 = Disarm must disarm"


@pytest.mark.parametrize("px4", ["1.17", "main"])
@pytest.mark.parametrize("value", [0, 1, 2])
def test_5_1_v117_stick_action_without_manual_control_becomes_nav_rcl_act(
    px4: str, value: int
) -> None:
    """5.1 (1.17+): a Position/Altitude/Stabilized action with manual control lost is replaced
    by the NAV_RCL_ACT action (default 2 = Return)."""
    trs = _lose(
        px4,
        extra=[flags(0.0, manual_control_signal_lost=True)],
        COM_OBL_RC_ACT=float(value),
    )
    assert [tr.action for tr in of("failsafe", trs)] == ["AUTO_RTL"]


@pytest.mark.parametrize("px4", ["1.14", "1.15", "1.16"])
def test_5_1_rc_not_consulted_before_117(px4: str) -> None:
    """5.1 / D4: 1.14-1.16 apply COM_OBL_RC_ACT whatever the RC state."""
    trs = _lose(px4, extra=[flags(0.0, manual_control_signal_lost=True)])
    assert [tr.action for tr in of("failsafe", trs)] == ["POSCTL"]


@pytest.mark.parametrize("value", [*V113_RC, OUT_OF_RANGE])
def test_5_2_v113_loss_action_with_rc(value: float) -> None:
    """5.2: RC present -> COM_OBL_RC_ACT (-1 Disabled .. 7 Lockdown)."""
    trs = _lose("1.13", COM_OBL_RC_ACT=float(value))
    if value == OUT_OF_RANGE:
        (failsafe,) = of("failsafe", trs)
        assert failsafe.unverified  # the switch default is not in the spec
        return
    action, nav = V113_RC[int(value)]
    if action == "NONE":
        assert not [tr for tr in of("failsafe", trs) if tr.nav_state not in (None, OFFBOARD)]
        return
    (failsafe,) = of("failsafe", trs)
    assert failsafe.action == action
    if nav is not None:
        assert failsafe.nav_state == nav


@pytest.mark.parametrize(
    ("value", "action"),
    [(0, "AUTO_LAND"), (1, "AUTO_LOITER"), (2, "AUTO_RTL"), (3, "TERMINATION")],
)
def test_5_2_v113_without_rc_uses_com_obl_act(value: int, action: str) -> None:
    """5.2: RC lost -> COM_OBL_ACT (0 Land, 1 Hold, 2 Return, 3 Terminate); COM_OBL_RC_ACT
    ignored."""
    trs = _lose(
        "1.13",
        extra=[flags(0.0, manual_control_signal_lost=True)],
        COM_OBL_ACT=float(value),
        COM_OBL_RC_ACT=1.0,
    )
    assert [tr.action for tr in of("failsafe", trs)] == [action]


def test_5_2_v113_rc_exception_bit_uses_com_obl_act() -> None:
    """5.2: RC present but COM_RCL_EXCEPT bit 2 -> COM_OBL_ACT (default 0 Land)."""
    trs = _lose("1.13", COM_RCL_EXCEPT=4.0)
    assert [tr.action for tr in of("failsafe", trs)] == ["AUTO_LAND"]


@pytest.mark.parametrize("value", [*V113_RC, OUT_OF_RANGE])
def test_5_2_v111_loss_action_is_modelled_like_113_and_unverified(value: float) -> None:
    """15 / 2.2: v1.11's loss action was not read line by line: modelled as 1.13, unverified."""
    trs = _lose("1.11", COM_OBL_RC_ACT=float(value))
    for failsafe in of("failsafe", trs):
        assert failsafe.unverified


@pytest.mark.parametrize("value", list(LEGACY_RC))
def test_5_3_legacy_loss_timeout_action_with_rc(value: float) -> None:
    """5.3: after 500 ms + COM_OF_LOSS_T (default 0 = at once) COM_OBL_RC_ACT applies (0-5);
    other values keep the stage-1 behaviour (POSCTL with a global position)."""
    trs = _lose("legacy", COM_OBL_RC_ACT=float(value))
    action, nav = LEGACY_RC[value]
    failsafes = of("failsafe", trs)
    assert failsafes, "legacy must fail safe 500 ms after the last setpoint"
    assert failsafes[0].t == pytest.approx(1.5)
    assert (failsafes[-1].action, failsafes[-1].nav_state) == (action, nav)


def test_5_3_legacy_two_stages_with_com_of_loss_t() -> None:
    """5.3: stage 1 (POSCTL with RC) at 500 ms, the configured action COM_OF_LOSS_T later."""
    trs = _lose("legacy", COM_OF_LOSS_T=1.0, COM_OBL_RC_ACT=4.0)
    assert [(round(tr.t, 3), tr.action) for tr in of("failsafe", trs)] == [
        (1.5, "POSCTL"),
        (2.5, "AUTO_LAND"),
    ]


@pytest.mark.parametrize(
    ("value", "action"), [(0, "AUTO_LAND"), (1, "AUTO_LOITER"), (2, "AUTO_RTL"), (5, "AUTO_LOITER")]
)
def test_5_3_legacy_without_rc_uses_com_obl_act(value: int, action: str) -> None:
    """5.3: no RC: COM_OBL_ACT 0 Land, 1 Loiter, 2 Return; out of 0-2 the stage-1 behaviour
    (AUTO_LOITER with a global position)."""
    trs = _lose(
        "legacy", extra=[flags(0.0, manual_control_signal_lost=True)], COM_OBL_ACT=float(value)
    )
    assert of("failsafe", trs)[-1].action == action


@pytest.mark.parametrize("px4", TICK)
def test_5_1_degradation_without_position_estimate(px4: str) -> None:
    """5.1: Position cannot run without a position estimate: the chain falls to Altitude."""
    trs = _lose(
        px4,
        extra=[flags(1.5, local_position_valid=False, local_velocity_valid=False)],
    )
    (failsafe,) = of("failsafe", trs)
    assert failsafe.action == "ALTCTL"
    assert failsafe.unverified  # the mode requirements are fuzzoff's approximation


@pytest.mark.parametrize("px4", TICK)
def test_5_1_terminate_never_clears(px4: str) -> None:
    """5.1: Terminate never clears, even when the stream comes back."""
    events = [in_offboard(), *stream(0.0, 1.0), *stream(3.0, 3.5)]
    trs = run(px4, events, params={"COM_OBL_RC_ACT": 6.0}, t_end=4.0)
    assert of("offboard_resumed", trs) == []


@pytest.mark.parametrize("px4", ["1.17", "main"])
def test_5_1_nav_rcl_act_disabled_gives_no_failsafe_unverified(px4: str) -> None:
    """5.1: NAV_RCL_ACT 0 as the replacement action: no failsafe is raised (presumably stays in
    OFFBOARD without a signal; unverified in SITL)."""
    trs = _lose(px4, extra=[flags(0.0, manual_control_signal_lost=True)], NAV_RCL_ACT=0.0)
    (failsafe,) = of("failsafe", trs)
    assert failsafe.action == "NONE" and failsafe.unverified
    assert failsafe.nav_state == OFFBOARD
