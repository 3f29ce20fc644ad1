"""A UDP proxy between a third-party MAVLink client (MAVSDK's server) and PX4 that records both
directions as a tlog, as ``Link`` records its own exchange.

PX4's onboard link sends to ``14540 + N``: the proxy listens there, and forwards PX4's datagrams
to the client's port; the client's answers come back to the proxy, which sends them on to PX4's
listening port ``14580 + N`` from the same socket PX4 sends to, so that PX4 sees one peer.
Datagrams are forwarded unchanged; pymavlink parses a copy of each direction for the recording
(a ``development``-dialect parser per direction), and PX4's TIMESYNC/SYSTEM_TIME feed the clock
the records are stamped with.
"""

from __future__ import annotations

import os
import selectors
import socket
import threading
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")  # formats.md 7.2: before any pymavlink import

from pymavlink.dialects.v20 import development as mavlink

from fuzzoff.sitl.clock import PX4Clock
from fuzzoff.sitl.recorder import TlogRecorder

MAX_DATAGRAM = 65535


class RecordingProxy:
    def __init__(self, px4_listen: int, px4_send: int, client_port: int, tlog: Path) -> None:
        self.px4_addr = ("127.0.0.1", px4_listen)
        self.client_addr = ("127.0.0.1", client_port)
        self.px4_side = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.px4_side.bind(("127.0.0.1", px4_send))
        self.client_side = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.client_side.bind(("127.0.0.1", 0))
        self.clock = PX4Clock()
        self.recorder = TlogRecorder(tlog, clock=self._stamp)
        self._from_px4: Any = mavlink.MAVLink(None)
        self._from_client: Any = mavlink.MAVLink(None)
        for parser in (self._from_px4, self._from_client):
            parser.robust_parsing = True
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="fuzzoff-proxy", daemon=True)
        self.packets = [0, 0]

    def _stamp(self) -> float:
        return self.clock.now()

    def start(self) -> RecordingProxy:
        self._thread.start()
        return self

    def _record(self, parser: Any, data: bytes, from_px4: bool) -> None:
        try:
            messages = parser.parse_buffer(data) or []
        except mavlink.MAVError:
            return
        for msg in messages:
            if from_px4:
                self.clock.observe(msg)
            if self.clock.synced:
                self.recorder.write(msg)

    def _run(self) -> None:
        sel = selectors.DefaultSelector()
        sel.register(self.px4_side, selectors.EVENT_READ, True)
        sel.register(self.client_side, selectors.EVENT_READ, False)
        while not self._stop.is_set():
            for key, _ in sel.select(0.1):
                sock: socket.socket = key.fileobj  # type: ignore[assignment]
                try:
                    data, _addr = sock.recvfrom(MAX_DATAGRAM)
                except OSError:
                    continue
                if key.data:
                    self.client_side.sendto(data, self.client_addr)
                    self.packets[0] += 1
                    self._record(self._from_px4, data, True)
                else:
                    self.px4_side.sendto(data, self.px4_addr)
                    self.packets[1] += 1
                    self._record(self._from_client, data, False)
        sel.close()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        self.recorder.close()
        self.px4_side.close()
        self.client_side.close()

    def __enter__(self) -> RecordingProxy:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()
