"""``write_mcap``: events -> a ROS 2 MCAP file through ``mcap_ros2``'s writer (formats.md 4.3).

The file embeds the px4_msgs definitions of ``release`` (a ``ros2msg`` schema per type), as
rosbag2's MCAP plugin does. ``payload_release`` encodes the payloads with another release's
definitions while still embedding ``release``'s: the wrong-release recording of formats.md 2.3,
for tests and the corpus (a dict: per message name, e.g. ``{"VehicleControlMode": "1.15"}``).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType
from mcap_ros2.writer import Writer

from fuzzoff.events import Event
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.ros2msgs.messages import (
    START_NS,
    Px4Message,
    RawMessage,
    encode,
    log_time,
    merged,
    payload_for,
    to_messages,
)


def write_mcap(
    path: str | Path,
    events: Iterable[Event],
    *,
    release: str = "main",
    payload_release: str | dict[str, str] | None = None,
    extra: Iterable[RawMessage] = (),
    start_ns: int = START_NS,
    chunk_size: int = 1024 * 1024,
    compression: CompressionType = CompressionType.ZSTD,
) -> Path:
    """Write ``events`` (and ``extra`` raw messages) as a ROS 2 MCAP file; returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as fh:
        writer = Writer(fh, chunk_size=chunk_size, compression=compression)
        # mcap_ros2 encodes only through a registered schema; raw payloads (foreign types, or a
        # payload of another release than the schema) go through its underlying mcap writer.
        raw_writer: Any = writer._writer
        schemas: dict[str, Any] = {}
        channels: dict[str, int] = {}
        raw_schemas: dict[str, int] = {}

        def channel(topic: str, msgtype: str, msgdef: str) -> int:
            if topic not in channels:
                if msgtype not in raw_schemas:
                    raw_schemas[msgtype] = raw_writer.register_schema(
                        name=msgtype, encoding="ros2msg", data=msgdef.encode()
                    )
                channels[topic] = raw_writer.register_channel(
                    topic=topic, message_encoding="cdr", schema_id=raw_schemas[msgtype]
                )
            return channels[topic]

        for item in merged(to_messages(events, release, start_ns), extra, start_ns):
            stamp = log_time(item, start_ns)
            if isinstance(item, RawMessage):
                cid = channel(item.topic, item.msgtype, item.msgdef)
                raw_writer.add_message(
                    channel_id=cid, log_time=stamp, data=item.data, publish_time=stamp
                )
            elif (other := payload_for(payload_release, item.message)) is not None:
                _write_other_release(item, other, channel, raw_writer, stamp)
            else:
                schema = schemas.get(item.typename)
                if schema is None:
                    text = px4_msgs.definition(release, item.message) or ""
                    schema = schemas[item.typename] = writer.register_msgdef(item.typename, text)
                writer.write_message(item.topic, schema, item.values, stamp, stamp)
        writer.finish()  # type: ignore[no-untyped-call]
    return path


def _write_other_release(
    item: Px4Message, payload_release: str, channel: Any, raw_writer: Any, stamp: int
) -> None:
    text = px4_msgs.definition(item.release, item.message)
    payload_text = px4_msgs.definition(payload_release, item.message)
    if text is None or payload_text is None:
        raise ValueError(f"{item.message} is not in both {item.release} and {payload_release}")
    data = encode(item, payload_release)
    cid = channel(item.topic, item.typename, text)
    raw_writer.add_message(channel_id=cid, log_time=stamp, data=data, publish_time=stamp)
