"""``write_rosbag2``: events -> a ROS 2 bag folder through rosbags' writer (formats.md 4.3, 5).

``storage`` is ``sqlite3`` or ``mcap``; the bag embeds ``release``'s px4_msgs definitions
(sqlite schema 4 ``message_definitions``, MCAP schemas) unless ``definitions=False``, which makes
a Humble-style bag: sqlite schema 3, no ``message_definitions`` table, metadata version 5 (rosbags
writes only Iron-style bags, so the Humble form is derived from its output).
``payload_release`` encodes payloads with another release while declaring ``release``.
"""

from __future__ import annotations

import re
import sqlite3
from collections.abc import Iterable
from pathlib import Path
from typing import Any, Literal

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from fuzzoff.events import Event
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.ros2msgs.messages import (
    START_NS,
    RawMessage,
    encode,
    log_time,
    merged,
    payload_for,
    to_messages,
)

Storage = Literal["sqlite3", "mcap"]
_PLUGINS = {"sqlite3": StoragePlugin.SQLITE3, "mcap": StoragePlugin.MCAP}


def write_rosbag2(
    path: str | Path,
    events: Iterable[Event],
    *,
    storage: Storage = "sqlite3",
    release: str = "main",
    definitions: bool = True,
    payload_release: str | dict[str, str] | None = None,
    extra: Iterable[RawMessage] = (),
    start_ns: int = START_NS,
) -> Path:
    """Write a bag folder at ``path`` (which must not exist); returns the folder."""
    path = Path(path)
    if not definitions and storage != "sqlite3":
        raise ValueError("a bag without definitions is a sqlite3 (Humble-style) bag")
    path.parent.mkdir(parents=True, exist_ok=True)
    connections: dict[str, Any] = {}
    with Writer(path, version=8 if not definitions else 9, storage_plugin=_PLUGINS[storage]) as w:

        def connection(topic: str, msgtype: str, msgdef: str) -> Any:
            if topic not in connections:
                rihs01 = _rihs01(msgtype, msgdef)
                connections[topic] = w.add_connection(topic, msgtype, msgdef=msgdef, rihs01=rihs01)
            return connections[topic]

        for item in merged(to_messages(events, release, start_ns), extra, start_ns):
            stamp = log_time(item, start_ns)
            if isinstance(item, RawMessage):
                w.write(connection(item.topic, item.msgtype, item.msgdef), stamp, item.data)
                continue
            text = px4_msgs.definition(release, item.message) or ""
            data = encode(item, payload_for(payload_release, item.message))
            w.write(connection(item.topic, item.typename, text), stamp, data)
    if not definitions:
        _humble(path)
    return path


def _rihs01(msgtype: str, msgdef: str) -> str:
    """The type hash rosbags wants for a connection (from the definition where it parses)."""
    try:
        store = get_typestore(Stores.ROS2_HUMBLE)
        if msgtype not in store.fielddefs:
            store.register(get_types_from_msg(msgdef, msgtype))
        return str(store.hash_rihs01(msgtype))
    except Exception:
        return "RIHS01_" + "0" * 64


def _humble(path: Path) -> None:
    """Turn rosbags' schema-4 sqlite bag into the Humble form (schema 3, no definitions)."""
    for db_path in path.glob("*.db3"):
        db = sqlite3.connect(db_path)
        try:
            db.execute("DROP TABLE IF EXISTS message_definitions")
            db.execute("UPDATE schema SET schema_version = 3, ros_distro = 'humble'")
            db.commit()
        finally:
            db.close()
    meta = path / "metadata.yaml"
    text = meta.read_text(encoding="utf-8")
    text = re.sub(r"^(\s*)version: \d+", r"\1version: 5", text, count=1, flags=re.MULTILINE)
    text = re.sub(
        r"^\s*type_description_hash:.*\n(?:\s+RIHS01_\S*\n)?", "", text, flags=re.MULTILINE
    )
    text = re.sub(r"^\s*ros_distro:.*\n", "", text, flags=re.MULTILINE)
    meta.write_text(text, encoding="utf-8")
