"""Stream a tlog's sent MAVLink packets to a live endpoint (a PX4 SITL) at their recorded timing.

The packets are the recording's own bytes (pymavlink parses the tlog and gives each message's
buffer back), so what arrives is exactly what the reproducer holds. Only what the companion or
a ground station sent is streamed: the autopilot's own messages (``--autopilot`` sysid/compid)
are the recorded answers, not part of the stream.
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

os.environ.setdefault("MAVLINK20", "1")  # formats.md 7.2: before any pymavlink import

from pymavlink import mavutil


class TargetError(ValueError):
    """A ``--to`` value that is not ``udp:HOST:PORT``."""


def parse_target(text: str) -> tuple[str, int]:
    scheme, _, rest = text.partition(":")
    host, _, port = rest.rpartition(":")
    if scheme != "udp" or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise TargetError(f"--to {text!r}: expected udp:HOST:PORT (e.g. udp:127.0.0.1:14540)")
    return host, int(port)


@dataclass(frozen=True, slots=True)
class Packet:
    t: float
    """Seconds from the first streamed packet."""
    data: bytes
    name: str


def sent_packets(path: Path, autopilot: tuple[int, int] = (1, 1)) -> list[Packet]:
    """The non-autopilot packets of a tlog with their times (raises ``OSError``/``ValueError``
    for a file pymavlink cannot read as a tlog)."""
    log = mavutil.mavlink_connection(str(path), notimestamps=False, robust_parsing=True)
    out: list[Packet] = []
    t0: float | None = None
    try:
        while True:
            msg = log.recv_msg()
            if msg is None:
                break
            if msg.get_type() == "BAD_DATA":
                continue
            if (msg.get_srcSystem(), msg.get_srcComponent()) == autopilot:
                continue
            stamp = float(getattr(msg, "_timestamp", 0.0))
            t0 = stamp if t0 is None else t0
            out.append(Packet(stamp - t0, bytes(msg.get_msgbuf()), msg.get_type()))
    finally:
        log.close()
    return out


def stream(
    packets: list[Packet],
    host: str,
    port: int,
    *,
    speed: float = 1.0,
    on_packet: Callable[[Packet], None] | None = None,
) -> int:
    """Send ``packets`` to ``host:port`` over UDP at their times (``speed`` x); the count."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        start = time.monotonic()
        for packet in packets:
            due = start + packet.t / speed
            delay = due - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            sock.sendto(packet.data, (host, port))
            if on_packet is not None:
                on_packet(packet)
    return len(packets)
