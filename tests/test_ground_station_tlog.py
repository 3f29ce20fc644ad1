"""Ground-station tlogs (no companion setpoints) and manual control read from a tlog.

The logs are packed by pymavlink as PX4 and QGroundControl send them: PX4 (1/1) with its
HEARTBEAT, AUTOPILOT_VERSION, SYS_STATUS and STATUSTEXT, QGC (255/190) with its own HEARTBEAT
and, where a joystick is used, MANUAL_CONTROL.
"""

from __future__ import annotations

import json
import os
import struct
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")

from pymavlink.dialects.v20 import development as mavlink

from fuzzoff.engine import Timeline, lint_file
from fuzzoff.formats.tlog.writer import DEFAULT_START_US, encode_px4_version
from fuzzoff.modes import nav_state_to_custom_mode
from tests.helpers import run_cli

PX4 = (1, 1)
QGC = (255, 190)
COMPANION = (1, 191)
LOITER, OFFBOARD, RTL, LAND = 4, 14, 5, 18
RC_BIT = 1 << 16


class _Log:
    """Records packed by pymavlink, one encoder per sender (each keeps its own sequence)."""

    def __init__(self) -> None:
        self.records: list[tuple[float, bytes]] = []
        self.links: dict[tuple[int, int], Any] = {}

    def add(self, t: float, sender: tuple[int, int], msg: Any) -> None:
        link = self.links.get(sender)
        if link is None:
            link = self.links[sender] = mavlink.MAVLink(None, *sender)
        self.records.append((t, bytes(msg.pack(link))))

    def write(self, path: Path) -> Path:
        self.records.sort(key=lambda r: r[0])
        path.write_bytes(
            b"".join(
                struct.pack(">Q", DEFAULT_START_US + round(t * 1e6)) + p for t, p in self.records
            )
        )
        return path


def _heartbeat(nav_state: int, armed: bool) -> Any:
    base = 1 | (128 if armed else 0)
    return mavlink.MAVLink_heartbeat_message(2, 12, base, nav_state_to_custom_mode(nav_state), 4, 3)


def _flight(
    release: str,
    modes: list[tuple[float, int, bool]],
    *,
    rc: bool | None,
    texts: tuple[tuple[float, str], ...] = (),
    joystick: bool = False,
    end: float = 20.0,
) -> _Log:
    """PX4's side of a flight as a ground station logs it: ``modes`` (from t, nav_state,
    armed) in 1 Hz heartbeats; SYS_STATUS at 2 Hz with the RC bit as ``rc`` says (None: no
    SYS_STATUS at all)."""
    log = _Log()
    version = encode_px4_version(release)
    log.add(0.0, QGC, mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 4, 3))
    log.add(
        0.01,
        PX4,
        mavlink.MAVLink_autopilot_version_message(
            0, version, 0, 0, 0, [0] * 8, [0] * 8, [0] * 8, 0, 0, 0, [0] * 18
        ),
    )
    t = 0.1
    while t < end:
        nav, armed = next((n, a) for start, n, a in reversed(modes) if start <= t)
        log.add(t, PX4, _heartbeat(nav, armed))
        log.add(t + 0.3, QGC, mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 4, 3))
        t += 1.0
    if rc is not None:
        present = 0x300402F | (RC_BIT if rc else 0)
        for i in range(int(end * 2)):
            log.add(
                i * 0.5 + 0.2,
                PX4,
                mavlink.MAVLink_sys_status_message(
                    present, present, present, 200, 12000, -1, -1, 0, 0, 0, 0, 0, 0
                ),
            )
    if joystick:
        for i in range(int(end * 10)):
            log.add(i * 0.1 + 0.05, QGC, mavlink.MAVLink_manual_control_message(1, 0, 0, 500, 0, 0))
    for at, text in texts:
        log.add(at, PX4, mavlink.MAVLink_statustext_message(2, text.encode()))
    return log


def _lint(path: Path, *args: str) -> tuple[int, list[dict[str, Any]]]:
    result = run_cli(["lint", str(path), "--format", "json", *args])
    assert result.returncode in (0, 1), result.stderr
    return result.returncode, json.loads(result.stdout)["files"][0]["findings"]


def test_a_ground_station_log_gives_one_ofb002_and_no_stream_finding(tmp_path: Path) -> None:
    # QGC's log of a clean offboard flight: OFFBOARD armed for 10 s, then AUTO_LAND
    log = _flight(
        "1.16.2", [(0.0, LOITER, False), (4.0, OFFBOARD, True), (14.0, LAND, True)], rc=False
    )
    _code, findings = _lint(log.write(tmp_path / "gcs.tlog"))
    codes = [f["code"] for f in findings]
    assert codes.count("OFB002") == 1
    (note,) = [f for f in findings if f["code"] == "OFB002"]
    assert "OFB101" in note["message"] and "OFB103" in note["message"]
    assert "companion" in note["message"]
    assert not {"OFB101", "OFB102", "OFB103", "OFB202"} & set(codes)
    assert all(f["severity"] == "info" for f in findings if f["code"] != "OFB702")


def test_a_ground_station_log_that_never_shows_offboard_says_nothing(tmp_path: Path) -> None:
    log = _flight("1.16.2", [(0.0, LOITER, False), (4.0, LOITER, True)], rc=True)
    code, findings = _lint(log.write(tmp_path / "loiter.tlog"))
    assert code == 0 and "OFB002" not in [f["code"] for f in findings]


def test_a_companion_command_means_the_link_is_recorded(tmp_path: Path) -> None:
    # the companion's own log with a switch and no setpoint at all: the stream rules judge it
    log = _flight("1.16.2", [(0.0, LOITER, True), (4.0, OFFBOARD, True)], rc=False, end=8.0)
    log.add(3.5, COMPANION, mavlink.MAVLink_command_long_message(1, 1, 176, 0, 1, 6, 0, 0, 0, 0, 0))
    _code, findings = _lint(log.write(tmp_path / "companion.tlog"))
    assert "OFB102" in [f["code"] for f in findings]


def _gate(path: Path) -> Timeline:
    timelines: dict[str, Timeline] = {}
    lint_file(path, timelines=timelines)
    return timelines["1"]


def test_a_recorded_failsafe_is_the_loss_and_its_action_is_judged(tmp_path: Path) -> None:
    # PX4 1.17 without manual control: Return, as PX4 did in SITL
    modes = [(0.0, LOITER, False), (4.0, OFFBOARD, True), (12.0, RTL, True)]
    texts = ((11.3, "Failsafe activated\t"),)
    log = _flight("1.17.0", modes, rc=False, texts=texts)
    path = log.write(tmp_path / "rtl.tlog")
    _code, findings = _lint(path)
    assert "OFB202" not in [f["code"] for f in findings]
    lost = [tr for tr in _gate(path).transitions if tr.what == "signal_lost"]
    assert len(lost) == 1 and "recorded failsafe" in lost[0].message
    (failsafe,) = [tr for tr in _gate(path).transitions if tr.what == "failsafe"]
    assert failsafe.action == "AUTO_RTL"
    # with manual control present PX4 1.17 would have gone to Position: the model says so
    with_rc = _flight("1.17.0", modes, rc=True, texts=texts).write(tmp_path / "rc.tlog")
    _code, findings = _lint(with_rc)
    (disagrees,) = [f for f in findings if f["code"] == "OFB202"]
    assert "AUTO_RTL" in disagrees["message"] and "POSCTL" in disagrees["message"]


def test_leaving_offboard_without_a_failsafe_message_is_followed(tmp_path: Path) -> None:
    # a pilot's switch (RC, or another client) is not a loss
    modes = [(0.0, LOITER, False), (4.0, OFFBOARD, True), (12.0, RTL, True)]
    path = _flight("1.17.0", modes, rc=True).write(tmp_path / "switch.tlog")
    assert not [tr for tr in _gate(path).transitions if tr.what in ("signal_lost", "failsafe")]
    _code, findings = _lint(path)
    assert "OFB202" not in [f["code"] for f in findings]


def _companion_loss(rc: bool | None, joystick: bool = False) -> _Log:
    """The companion's log on 1.17: setpoints at 20 Hz, a switch, then the stream stops."""
    modes = [(0.0, LOITER, True), (3.0, OFFBOARD, True), (10.0, RTL, True)]
    log = _flight("1.17.0", modes, rc=rc, joystick=joystick, end=14.0)
    mask = 0b1001_1111_1000
    for i in range(160):
        t = 0.5 + i * 0.05
        log.add(
            t,
            COMPANION,
            mavlink.MAVLink_set_position_target_local_ned_message(
                round(t * 1000), 1, 1, 1, mask, 0, 0, -3, 0, 0, 0, 0, 0, 0, 0, 0
            ),
        )
    log.add(2.5, COMPANION, mavlink.MAVLink_command_long_message(1, 1, 176, 0, 1, 6, 0, 0, 0, 0, 0))
    return log


def _loss_finding(path: Path) -> str:
    _code, findings = _lint(path)
    (loss,) = [f for f in findings if f["code"] == "OFB103"]
    return str(loss["message"])


def test_manual_control_is_read_from_sys_status(tmp_path: Path) -> None:
    # PX4's SYS_STATUS says no RC receiver: 1.17 replaces Position by NAV_RCL_ACT (Return)
    message = _loss_finding(_companion_loss(rc=False).write(tmp_path / "norc.tlog"))
    assert "runs AUTO_RTL" in message
    message = _loss_finding(_companion_loss(rc=True).write(tmp_path / "rc.tlog"))
    assert "runs POSCTL" in message


def test_a_joystick_on_the_ground_station_is_manual_control(tmp_path: Path) -> None:
    message = _loss_finding(_companion_loss(rc=None, joystick=True).write(tmp_path / "joy.tlog"))
    assert "runs POSCTL" in message


def test_manual_control_not_in_the_recording_is_said_to_be_assumed(tmp_path: Path) -> None:
    path = _companion_loss(rc=None).write(tmp_path / "unknown.tlog")
    (failsafe,) = [tr for tr in _gate(path).transitions if tr.what == "failsafe"]
    assert "manual control assumed present (FUZZOFF_RC_PRESENT)" in failsafe.message
    recorded = _companion_loss(rc=False).write(tmp_path / "recorded.tlog")
    (failsafe,) = [tr for tr in _gate(recorded).transitions if tr.what == "failsafe"]
    assert "assumed" not in failsafe.message
