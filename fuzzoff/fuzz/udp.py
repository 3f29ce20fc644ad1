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
from typing import Any

os.environ.setdefault("MAVLINK20", "1")  # formats.md 7.2: before any pymavlink import

from pymavlink import mavutil


class TargetError(ValueError):
    """A ``--to`` value that is not ``udp:HOST:PORT``, or a host that cannot be resolved."""


USAGE = "expected udp:HOST:PORT (e.g. udp:127.0.0.1:14540, udp:[::1]:14540)"


def parse_target(text: str) -> tuple[str, int]:
    """HOST and PORT of ``udp:HOST:PORT``; an IPv6 address goes in brackets, as in a URL
    (``udp:[::1]:14540``), so that a missing port is not read from the address."""
    scheme, _, rest = text.partition(":")
    host, _, port = rest.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
        if not host or "[" in host or "]" in host:
            raise TargetError(f"--to {text!r}: {USAGE}")
    elif "[" in host or "]" in host or ":" in host:
        raise TargetError(f"--to {text!r}: an IPv6 address goes in brackets: {USAGE}")
    if scheme != "udp" or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise TargetError(f"--to {text!r}: {USAGE}")
    return host, int(port)


@dataclass(frozen=True, slots=True)
class Target:
    """Where the packets go: the address family and the socket address to send to."""

    host: str
    port: int
    family: int
    address: tuple[Any, ...]

    def __str__(self) -> str:
        return f"[{self.host}]:{self.port}" if ":" in self.host else f"{self.host}:{self.port}"


def target_for(text: str) -> Target:
    """Where ``udp:HOST:PORT`` sends to (IPv4 first where the host has both, as before IPv6
    was taken: a PX4 SITL listens on IPv4); ``TargetError`` when it is malformed or the host
    cannot be resolved."""
    host, port = parse_target(text)
    try:
        found = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)
    except (socket.gaierror, UnicodeError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise TargetError(f"--to {text!r}: cannot resolve host {host!r}: {reason}") from None
    family, _, _, _, address = min(found, key=lambda info: info[0] != socket.AF_INET)
    return Target(host, port, family, tuple(address))


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
    target: Target,
    *,
    speed: float = 1.0,
    on_packet: Callable[[Packet], None] | None = None,
) -> int:
    """Send ``packets`` to ``target`` over UDP at their times (``speed`` x); the count."""
    with socket.socket(target.family, socket.SOCK_DGRAM) as sock:
        start = time.monotonic()
        for packet in packets:
            due = start + packet.t / speed
            delay = due - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            sock.sendto(packet.data, target.address)
            if on_packet is not None:
                on_packet(packet)
    return len(packets)
