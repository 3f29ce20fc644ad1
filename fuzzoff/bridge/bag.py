"""The companion's side: each PX4 topic of a ROS 2 bag, its samples as the recording holds them.

rosbags' ``AnyReader`` reads the bag (either storage) and decodes each message with the
definitions the bag embeds. A sample keeps the receive time the recorder wrote (the host's
clock), the message's ``timestamp`` field (what the sender stamped, or PX4's time plus the
bridge's offset for PX4's outputs) and its other fields, flattened as PX4's ULog names them
(``position[0]``), for comparing a sent message with what PX4 logged.
"""

from __future__ import annotations

import re
from dataclasses import field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from fuzzoff.bridge import BridgeError
from fuzzoff.lean_dataclass import dataclass

BRIDGE_TOPIC = re.compile(r"/fmu/(in|out)/([a-z0-9_]+?)(?:_v\d+)?$")
"""``/fmu/in/trajectory_setpoint``, ``/fmu/out/vehicle_status_v4`` (any namespace before)."""
Direction = Literal["in", "out"]


@dataclass(frozen=True, slots=True)
class Sample:
    received_us: int
    """The recorder's receive time (the host's clock, µs)."""
    stamp_us: int
    """The message's ``timestamp`` field."""
    fields: dict[str, Any]


@dataclass(slots=True)
class BagTopic:
    topic: str
    """As recorded (``/fmu/in/offboard_control_mode``)."""
    name: str
    """PX4's uORB topic (``offboard_control_mode``)."""
    direction: Direction
    samples: list[Sample] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class Bag:
    path: str
    first_us: int
    """The first message's receive time: findings count from it, as a lint of the bag does."""
    last_us: int
    topics: dict[str, BagTopic]
    """By uORB name."""


def flatten(message: Any) -> dict[str, Any]:
    """A decoded message's plain fields as ULog names them (arrays as ``name[i]``)."""
    out: dict[str, Any] = {}
    for name in getattr(message, "__dataclass_fields__", {}):
        if name.startswith("__"):
            continue
        value = getattr(message, name)
        if isinstance(value, np.ndarray):
            for i, item in enumerate(value.tolist()):
                out[f"{name}[{i}]"] = item
        elif isinstance(value, (bool, int, float)):
            out[name] = value
    return out


def read_bag(path: Path) -> Bag:
    """The PX4 topics of the bag folder ``path``; BridgeError when it cannot be read."""
    from rosbags.highlevel import AnyReader

    if not path.is_dir():
        raise BridgeError(f"{path}: --with compares a ROS 2 bag folder with PX4's ULog")
    topics: dict[str, BagTopic] = {}
    try:
        with AnyReader([path]) as reader:
            wanted = []
            for connection in reader.connections:
                match = BRIDGE_TOPIC.search(connection.topic)
                if match is None:
                    continue
                name = match.group(2)
                direction: Direction = "in" if match.group(1) == "in" else "out"
                known = topics.setdefault(name, BagTopic(connection.topic, name, direction))
                if known.topic != connection.topic:
                    raise BridgeError(
                        f"{path}: {known.topic} and {connection.topic}: --with compares one"
                        " vehicle's topics with its ULog, this bag holds several"
                    )
                wanted.append(connection)
            first = last = None
            for connection, received_ns, raw in reader.messages(connections=wanted):
                message = reader.deserialize(raw, connection.msgtype)
                name = BRIDGE_TOPIC.search(connection.topic).group(2)  # type: ignore[union-attr]
                received = received_ns // 1000
                first = received if first is None else min(first, received)
                last = received if last is None else max(last, received)
                stamp = int(getattr(message, "timestamp", 0))
                topics[name].samples.append(Sample(received, stamp, flatten(message)))
    except BridgeError:
        raise
    except Exception as exc:  # rosbags' errors have no common base
        raise BridgeError(f"{path}: cannot read the bag ({exc})") from None
    if first is None or last is None:
        raise BridgeError(f"{path}: no PX4 topic (/fmu/in, /fmu/out) in the bag")
    for topic in topics.values():
        topic.samples.sort(key=lambda s: s.received_us)
    return Bag(str(path), first, last, topics)
