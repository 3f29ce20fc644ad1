"""main's COM_POS_FS_ACT (gate spec 16 S11): 1 (Terminate) skips Descend at the end of the
offboard-loss degradation chain; 1.18 and older have no such parameter."""

from __future__ import annotations

import pytest

from fuzzoff import releases
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.failsafe import loss_action
from fuzzoff.gate.params import default_params

NO_POSITION = Estimates(local_position=False, local_velocity=False, global_position=False)


@pytest.mark.parametrize(
    ("px4", "value", "action"),
    [
        ("main", 0.0, "DESCEND"),
        ("main", 1.0, "TERMINATION"),
        ("1.18", 1.0, "DESCEND"),
        ("1.17", 1.0, "DESCEND"),
    ],
)
def test_com_pos_fs_act_ends_the_chain_on_main_only(px4: str, value: float, action: str) -> None:
    params = default_params(px4) | {"COM_OBL_RC_ACT": 4.0, "COM_POS_FS_ACT": value}
    found = loss_action(releases.get(px4), "mc", params, NO_POSITION)
    assert found.action == action
    assert ("COM_POS_FS_ACT 1" in found.note) == (px4 == "main" and value == 1.0)


def test_main_defaults_to_descend() -> None:
    assert default_params("main")["COM_POS_FS_ACT"] == 0.0
    assert "COM_POS_FS_ACT" not in default_params("1.18")


def test_the_1_18_head_s_unsolicited_gripper_ack_is_no_client_s_ack() -> None:
    """The 1.18 head acks MAV_CMD_DO_GRIPPER (211) about 1.3 s after boot with no command sent
    (seen on SITL, 2026-12): the model judges no request by it."""
    from fuzzoff.events import CommandAck
    from tests.gate.streams import OFFBOARD, arm, run, status, stream, switch_offboard

    gripper = CommandAck(t=1.3, vehicle="1", command=211, result=0)
    events = [status(0.0, 4, False, 4), gripper, *stream(0.0, 4.0), switch_offboard(2.0), arm(2.5)]
    trs = run("1.18", events, t_end=4.0)
    assert not [tr for tr in trs if tr.what == "disagreement"]
    assert [tr.nav_state for tr in trs if tr.what == "arm_accepted"] == [OFFBOARD]
