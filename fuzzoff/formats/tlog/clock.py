"""When a tlog started on the wall clock: the ground station's Unix time on its first record."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def start_s(path: Path) -> float | None:
    from pymavlink import mavutil

    log: Any = mavutil.mavlink_connection(str(path), robust_parsing=True)
    try:
        msg = log.recv_msg()
        return None if msg is None else float(msg._timestamp)
    finally:
        log.close()
