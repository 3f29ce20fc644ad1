"""A recorded ROS 2 bag's messages to PX4 (``/fmu/in``), as a plan to send over DDS.

``plan_from_bag`` reads the bag (a rosbag2 folder, mcap or sqlite3 storage) with rosbags and
keeps every message on a PX4 input topic (``/fmu/in/...``, any namespace: it is sent to the
bundle's own, none) with its offset from the first one, its bytes and its definition (the bag's
schema, else the release's bundled ``.msg``). The plan is written as JSON beside the flight's
outputs, since the flight runs in a namespace that may not see the bag's folder.
"""

from __future__ import annotations

import base64
import json
from pathlib import Path

from rosbags.rosbag2 import Reader

from fuzzoff.formats import px4_msgs
from fuzzoff.formats.ros2msgs.topics import parse_topic
from fuzzoff.lean_dataclass import dataclass


class ReplayError(Exception):
    """A bag that cannot be replayed: one line for the user."""


@dataclass(frozen=True, slots=True)
class Message:
    offset_s: float
    topic: str
    """The topic it goes to: ``/fmu/in/<name>[_vN]``, without the recorded namespace."""
    message: str
    msgdef: str
    data: bytes


@dataclass(frozen=True, slots=True)
class Plan:
    source: str
    messages: tuple[Message, ...]


def plan_from_bag(path: Path, release: str) -> Plan:
    """The ``/fmu/in`` messages of the bag at ``path``; ``release``'s folder of ``.msg`` files
    defines those the bag carries no definition for."""
    folder = px4_msgs.release_for(release) or "main"
    try:
        reader = Reader(path)
        reader.open()
    except Exception as exc:
        raise ReplayError(f"{path}: not a rosbag2 folder rosbags can read ({exc})") from None
    try:
        chosen = {}
        for connection in reader.connections:
            ref = parse_topic(connection.topic)
            if ref is None or ref.direction != "in" or ref.legacy:
                continue
            message = connection.msgtype.rsplit("/", 1)[-1]
            msgdef = connection.msgdef.data or px4_msgs.definition(folder, message) or ""
            if not msgdef:
                raise ReplayError(f"{path}: no definition of {message} to send it with")
            suffix = f"_v{ref.version}" if ref.version else ""
            chosen[connection.id] = (f"/fmu/in/{ref.name}{suffix}", message, msgdef)
        rows = [
            (stamp, chosen[c.id], bytes(data))
            for c, stamp, data in reader.messages()
            if c.id in chosen
        ]
    finally:
        reader.close()
    if not rows:
        raise ReplayError(f"{path}: no message on a PX4 input topic (/fmu/in/...)")
    rows.sort(key=lambda row: row[0])
    first = rows[0][0]
    messages = tuple(
        Message((stamp - first) / 1e9, topic, message, msgdef, data)
        for stamp, (topic, message, msgdef), data in rows
    )
    return Plan(str(path), messages)


def save_plan(plan: Plan, target: Path) -> Path:
    rows = [
        {
            "offset_s": m.offset_s,
            "topic": m.topic,
            "message": m.message,
            "msgdef": m.msgdef,
            "data": base64.b64encode(m.data).decode("ascii"),
        }
        for m in plan.messages
    ]
    target.write_text(json.dumps({"source": plan.source, "messages": rows}))
    return target


def load_plan(path: Path) -> Plan:
    data = json.loads(path.read_text())
    messages = tuple(
        Message(
            row["offset_s"],
            row["topic"],
            row["message"],
            row["msgdef"],
            base64.b64decode(row["data"]),
        )
        for row in data["messages"]
    )
    return Plan(data["source"], messages)
