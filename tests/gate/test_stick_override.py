"""The sticks taking over OFFBOARD (gate spec 16 S1, seen on PX4 SITL 1.17.0, the 1.18 head and
main): a steady ramp ends OFFBOARD on 1.18 and main, a step or a fast swing does not; 1.17
keeps OFFBOARD unless COM_RC_OVERRIDE has bit 1."""

from __future__ import annotations

import pytest

from fuzzoff.events import ManualControl
from fuzzoff.gate import GateModel
from tests.gate.streams import OFFBOARD, POSCTL, in_offboard, model, run, stream

RATE = 20.0
"""A MAVLink joystick at 20 Hz."""


def sticks(t0: float, pitches: list[float]) -> list[ManualControl]:
    return [
        ManualControl(t=round(t0 + i / RATE, 6), vehicle="1", pitch=p)
        for i, p in enumerate(pitches)
    ]


def ramp(t0: float, speed: float, seconds: float = 0.6) -> list[ManualControl]:
    """Centred, then pitch rising at ``speed`` per second, then held."""
    n = round(seconds * RATE)
    rising = [min(1.0, speed * i / RATE) for i in range(n + 1)]
    return sticks(t0, [0.0] * 4 + rising + rising[-1:] * 4)


STEP = sticks(2.0, [0.0] * 4 + [0.6] * 40)
SWING = sticks(2.0, [0.0] * 4 + [0.8 if (i // 5) % 2 else -0.8 for i in range(40)])


def final_nav(px4: str, joystick: list[ManualControl], **params: float) -> int | None:
    gate: GateModel = model(px4, **params)
    run(px4, [in_offboard(), *stream(0.0, 5.0), *joystick], model=gate, t_end=5.0)
    return gate.nav_state


@pytest.mark.parametrize("px4", ["1.18", "main"])
def test_a_steady_ramp_hands_offboard_to_position_on_1_18_and_main(px4: str) -> None:
    gate = model(px4)
    trs = run(px4, [in_offboard(), *stream(0.0, 5.0), *ramp(2.0, 2.0)], model=gate, t_end=5.0)
    (override,) = [tr for tr in trs if tr.reason == "stick override"]
    assert "MAN_OVERRIDE_SPD 1" in override.message and override.spec == "16"
    # the third same-direction sample after the ramp starts, while the stream goes on
    assert 2.2 < override.t < 2.4
    assert gate.nav_state == POSCTL and gate.user_intention == POSCTL


@pytest.mark.parametrize("px4", ["1.18", "main"])
@pytest.mark.parametrize("joystick", [STEP, SWING], ids=["step", "swing"])
def test_a_step_or_a_fast_swing_leaves_offboard_on_1_18(
    px4: str, joystick: list[ManualControl]
) -> None:
    assert final_nav(px4, joystick) == OFFBOARD


def test_a_ramp_slower_than_man_override_spd_or_a_negative_one_leaves_offboard() -> None:
    assert final_nav("1.18", ramp(2.0, 0.8)) == OFFBOARD
    assert final_nav("1.18", ramp(2.0, 2.0), MAN_OVERRIDE_SPD=-1.0) == OFFBOARD
    assert final_nav("1.18", ramp(2.0, 0.8), MAN_OVERRIDE_SPD=0.5) == POSCTL


@pytest.mark.parametrize("px4", ["1.14", "1.16", "1.17"])
def test_1_17_keeps_offboard_unless_com_rc_override_has_bit_1(px4: str) -> None:
    assert final_nav(px4, ramp(2.0, 2.0)) == OFFBOARD
    assert final_nav(px4, STEP) == OFFBOARD
    assert final_nav(px4, ramp(2.0, 2.0), COM_RC_OVERRIDE=3.0) == POSCTL
    assert final_nav(px4, STEP, COM_RC_OVERRIDE=2.0) == POSCTL
    assert final_nav(px4, ramp(2.0, 0.2), COM_RC_OVERRIDE=3.0) == OFFBOARD


def test_pxs_own_sticks_moving_verdict_wins_where_logged() -> None:
    logged = [
        ManualControl(t=2.0, vehicle="1", pitch=0.0, sticks_moving=False),
        ManualControl(t=2.2, vehicle="1", pitch=0.6, sticks_moving=True),
    ]
    assert final_nav("1.18", logged) == POSCTL
    assert final_nav("1.18", [*STEP[:6], ManualControl(t=3.0, vehicle="1", pitch=0.9)]) == OFFBOARD


@pytest.mark.parametrize("vehicle", ["fw", "rover-ackermann"])
def test_the_sticks_do_not_end_offboard_on_a_fixed_wing_or_rover(vehicle: str) -> None:
    gate = model("1.18", vehicle=vehicle)
    run("1.18", [in_offboard(), *stream(0.0, 5.0), *ramp(2.0, 2.0)], model=gate, t_end=5.0)
    assert gate.nav_state == OFFBOARD


def test_no_override_while_the_loss_failsafe_runs_and_none_after_the_switch_back() -> None:
    gate = model("1.18")
    # the stream stops at 1 s: failsafe from about 2.1 s; the ramp at 2.5 s changes nothing
    run("1.18", [in_offboard(), *stream(0.0, 1.0), *ramp(2.5, 2.0)], model=gate, t_end=4.0)
    assert gate.user_intention == OFFBOARD


def test_a_tlog_s_mavlink_joystick_is_read_as_px4_scales_it() -> None:
    """MANUAL_CONTROL x, y, r in thousandths; z 0..1000 is throttle -1..1 (500: centred)."""
    from fuzzoff.formats import open_source
    from tests.helpers import CORPORA

    with open_source(CORPORA / "sitl" / "sticks_moved-1.18.0-beta1-head.tlog") as source:
        source.probe()
        sticks = [e for e in source.events() if isinstance(e, ManualControl)]
    assert len(sticks) > 100 and {e.vehicle for e in sticks} == {"7"}
    assert max(e.pitch for e in sticks) == pytest.approx(0.6)
    assert (
        {e.roll for e in sticks} == {e.yaw for e in sticks} == {e.throttle for e in sticks} == {0.0}
    )
    assert all(e.sticks_moving is None for e in sticks)  # PX4's verdict is not in a tlog
