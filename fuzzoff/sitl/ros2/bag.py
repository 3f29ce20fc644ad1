"""What a ROS 2 recorder received, written as ``ros2 bag record`` writes it.

Each record is a sample's bytes exactly as they arrived over DDS (the CDR encapsulation header
first) with the time it was received (the recorder host's system clock, in ns since the
epoch, as rosbag2 stamps; the recorder polls its readers every 2 ms). The bag holds each
topic's ROS 2 name and type, its message definition (the schema: the release's ``.msg`` text
as ``fuzzoff/formats/px4_msgs`` bundles it, the wire fields and ``MESSAGE_VERSION`` without
px4_msgs' comments), and the QoS its writers offered as discovered. rosbags' writer writes
the bag, in ``mcap`` or ``sqlite3`` storage; both storages of one flight hold the same records.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable
from dataclasses import field
from pathlib import Path

from rosbags.interfaces import Qos
from rosbags.rosbag2 import StoragePlugin, Writer

from fuzzoff.formats.rosbag2.writer import Storage, _rihs01
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl.ros2.names import BridgeTopic

PLUGINS = {"sqlite3": StoragePlugin.SQLITE3, "mcap": StoragePlugin.MCAP}


@dataclass(frozen=True, slots=True)
class Record:
    topic: BridgeTopic
    data: bytes
    received_ns: int


@dataclass(slots=True)
class Recording:
    """The records of one flight, in the order they arrived (thread-safe to append)."""

    records: list[Record] = field(default_factory=list)
    offered: dict[str, list[Qos]] = field(default_factory=dict)
    """ROS 2 topic -> the QoS each of its writers offered."""
    _lock: threading.Lock = field(default_factory=threading.Lock)
    recording: bool = True

    def add(self, topic: BridgeTopic, data: bytes, received_ns: int) -> None:
        with self._lock:
            if self.recording:
                self.records.append(Record(topic, data, received_ns))

    def stop(self) -> None:
        with self._lock:
            self.recording = False

    def count(self, ros_topic: str) -> int:
        return sum(1 for r in self.records if r.topic.ros_topic == ros_topic)


def write_bag(
    path: Path, records: Iterable[Record], offered: dict[str, list[Qos]], storage: Storage
) -> Path:
    """Write ``records`` as a bag folder at ``path`` (which must not exist)."""
    ordered = sorted(records, key=lambda r: r.received_ns)
    with Writer(path, version=Writer.VERSION_LATEST, storage_plugin=PLUGINS[storage]) as writer:
        connections = {}
        for record in ordered:
            topic = record.topic
            if topic.ros_topic not in connections:
                connections[topic.ros_topic] = writer.add_connection(
                    topic.ros_topic,
                    topic.ros_type,
                    msgdef=topic.msgdef,
                    rihs01=_rihs01(topic.ros_type, topic.msgdef),
                    offered_qos_profiles=offered.get(topic.ros_topic, []),
                )
            writer.write(connections[topic.ros_topic], record.received_ns, record.data)
    return path
