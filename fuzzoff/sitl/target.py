"""``--to udp:HOST:PORT``: where a replay sends (``fuzzoff.sitl.replay`` does the sending).

PX4 SITL listens on 14580 (+ instance) and sends to 14540: a client sends to 14580.
"""

from __future__ import annotations

import socket
from typing import Any

from fuzzoff.lean_dataclass import dataclass


class TargetError(ValueError):
    """A ``--to`` value that is not ``udp:HOST:PORT``, or a host that cannot be resolved."""


USAGE = "expected udp:HOST:PORT (e.g. udp:127.0.0.1:14580, udp:[::1]:14580)"


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
