"""Synthetic tlogs for the tlog benchmark, fast to make at a million messages.

Every packet is built by pymavlink once (a few hundred variants per message type) and the
bytes are reused; only the 8-byte record timestamp changes from record to record. The stream
is a plausible offboard flight: a 50 Hz setpoint stream from the companion, the autopilot's
1 Hz HEARTBEAT (POSCTL, then OFFBOARD armed after an accepted DO_SET_MODE), and, for the mixed
log, telemetry (ATTITUDE, HIGHRES_IMU, LOCAL_POSITION_NED, ...) so that setpoints are a small
share of all messages.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")

from pymavlink.dialects.v20 import common as mavlink

from fuzzoff.formats.tlog.writer import DEFAULT_START_US, encode_px4_version
from fuzzoff.modes import nav_state_to_custom_mode

VARIANTS = 256
SETPOINT_PERIOD_US = 20_000
_TS = struct.Struct(">Q")


class _Capture:
    def __init__(self) -> None:
        self.last = b""

    def write(self, data: bytes) -> None:
        self.last = bytes(data)


def _packer(sysid: int, compid: int) -> Any:
    cap = _Capture()
    link = mavlink.MAVLink(cap, srcSystem=sysid, srcComponent=compid)

    def pack(msg: Any) -> bytes:
        link.send(msg)
        return cap.last

    return pack


def _templates() -> dict[str, list[bytes]]:
    ap = _packer(1, 1)
    cc = _packer(1, 191)
    out: dict[str, list[bytes]] = {}
    out["setpoint"] = [
        cc(
            mavlink.MAVLink_set_position_target_local_ned_message(
                i * 20, 1, 1, 1, 0x09F8, i * 0.01, 0.0, -2.0, 0, 0, 0, 0, 0, 0, 0.0, 0
            )
        )
        for i in range(VARIANTS)
    ]
    out["attitude"] = [
        ap(mavlink.MAVLink_attitude_message(i * 4, 0.01 * i, 0.02, 0.03, 0, 0, 0))
        for i in range(VARIANTS)
    ]
    out["imu"] = [
        ap(
            mavlink.MAVLink_highres_imu_message(
                i * 4000, 0.1, 0.2, -9.8, 0, 0, 0, 0.2, 0.0, 0.4, 1013.0, 0, 0, 20.0, 0xFFFF
            )
        )
        for i in range(VARIANTS)
    ]
    out["local"] = [
        ap(mavlink.MAVLink_local_position_ned_message(i * 4, 0.01 * i, 0, -2, 0, 0, 0))
        for i in range(VARIANTS)
    ]
    hb = mavlink.MAVLink_heartbeat_message
    out["hb_pos"] = [ap(hb(2, 12, 1, nav_state_to_custom_mode(2), 4, 3))]
    out["hb_ofb"] = [ap(hb(2, 12, 129, nav_state_to_custom_mode(14), 4, 3))]
    out["version"] = [
        ap(
            mavlink.MAVLink_autopilot_version_message(
                0, encode_px4_version("1.15.4"), 0, 0, 0, [0] * 8, [0] * 8, [0] * 8, 0, 0, 0
            )
        )
    ]
    out["switch"] = [cc(mavlink.MAVLink_command_long_message(1, 1, 176, 0, 1, 6, 0, 0, 0, 0, 0))]
    out["ack"] = [ap(mavlink.MAVLink_command_ack_message(176, 0, 0, 0, 1, 191))]
    return out


def records(messages: int, fillers_per_setpoint: int) -> Iterator[bytes]:
    """About ``messages`` records; each 20 ms tick has one setpoint and N telemetry packets."""
    tpl = _templates()
    filler_kinds = [tpl["attitude"], tpl["imu"], tpl["local"]]
    t = DEFAULT_START_US
    yield _TS.pack(t) + tpl["version"][0]
    count = 1
    tick = 0
    switch_tick = 100  # 2 s of stream before the switch
    while count < messages:
        stamp = _TS.pack(t)
        yield stamp + tpl["setpoint"][tick % VARIANTS]
        count += 1
        for k in range(fillers_per_setpoint):
            kind = filler_kinds[k % len(filler_kinds)]
            yield _TS.pack(t + 1000 + k) + kind[(tick + k) % VARIANTS]
            count += 1
        if tick % 50 == 0:
            hb = tpl["hb_ofb"] if tick > switch_tick else tpl["hb_pos"]
            yield _TS.pack(t + 5000) + hb[0]
            count += 1
        if tick == switch_tick:
            yield _TS.pack(t + 6000) + tpl["switch"][0]
            yield _TS.pack(t + 9000) + tpl["ack"][0]
            count += 2
        tick += 1
        t += SETPOINT_PERIOD_US


def generate(path: Path, messages: int, fillers_per_setpoint: int = 0) -> Path:
    """Write the log unless a file of that name already exists (the data are deterministic)."""
    if path.exists():
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".part")
    with tmp.open("wb") as fh:
        batch: list[bytes] = []
        for record in records(messages, fillers_per_setpoint):
            batch.append(record)
            if len(batch) >= 65536:
                fh.write(b"".join(batch))
                batch.clear()
        fh.write(b"".join(batch))
    tmp.rename(path)
    return path
