"""A ROS 2 recorder on DDS: readers of the flight's topics polled by one thread.

Each sample goes to the recording as it arrived (``bag.Recording``); PX4's status and acks are
also decoded for the flight's own decisions and its summary (``Watch``). Needs cyclonedds.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import field
from typing import Any

from cyclonedds.domain import DomainParticipant

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl.ros2.bag import Recording
from fuzzoff.sitl.ros2.dds import RawReader
from fuzzoff.sitl.ros2.names import BridgeTopic

POLL_S = 0.002


@dataclass(slots=True)
class Watch:
    """What PX4 said last, decoded for the flight's own decisions and its summary."""

    status: dict[str, Any] = field(default_factory=dict)
    acks: list[dict[str, Any]] = field(default_factory=list)
    modes: list[tuple[float, int, int, bool]] = field(default_factory=list)
    """(monotonic s, nav_state, arming_state, failsafe) at each change"""


class Recorder:
    """Readers of every topic polled by one thread; each sample's bytes to the recording."""

    def __init__(self, participant: DomainParticipant, topics: list[BridgeTopic]) -> None:
        self.readers = [RawReader(participant, t) for t in topics]
        self.recording: Recording | None = None
        self.watch = Watch()
        self.on_message: dict[str, Callable[[Any], None]] = {}
        """px4_msgs message -> a node's callback, given each one decoded as it arrives."""
        self.error: BaseException | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5.0)

    def _loop(self) -> None:
        try:
            while not self._stop.is_set():
                for reader in self.readers:
                    reader.take(self._deliver)
                time.sleep(POLL_S)
        except BaseException as exc:  # reported by the flight, which stops
            self.error = exc

    def _deliver(self, topic: BridgeTopic, data: bytes, received_ns: int) -> None:
        if self.recording is not None:
            self.recording.add(topic, data, received_ns)
        handler = self.on_message.get(topic.message)
        if handler is not None:
            handler(self._decode(topic, data))
        if topic.message == "VehicleStatus":
            self._status(self._decode(topic, data))
        elif topic.message == "VehicleCommandAck":
            ack = self._decode(topic, data)
            self.watch.acks.append(
                {"t": time.monotonic(), "command": ack.command, "result": ack.result}
            )

    def _decode(self, topic: BridgeTopic, data: bytes) -> Any:
        return next(r for r in self.readers if r.topic == topic).decode(data)

    def _status(self, status: Any) -> None:
        self.watch.status = {
            "nav_state": status.nav_state,
            "arming_state": status.arming_state,
            "failsafe": status.failsafe,
            "pre_flight_checks_pass": status.pre_flight_checks_pass,
        }
        key = (status.nav_state, status.arming_state, bool(status.failsafe))
        if not self.watch.modes or self.watch.modes[-1][1:] != key:
            self.watch.modes.append((time.monotonic(), *key))

    def offered(self) -> dict[str, list[Any]]:
        return {r.topic.ros_topic: list(r.offered.values()) for r in self.readers if r.offered}
