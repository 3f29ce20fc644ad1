"""MAVROS topics in ROS 2 recordings: decode, then ``mavros.convert`` turns each message
into the MAVLink event MAVROS sends PX4 (formats.md 6.1).

Definitions: the recording's own (MCAP schema, rosbag2 schema 4), else the shipped
``mavros_msgs`` (Humble-and-older ``.db3`` bags embed none, formats.md 3); the standard types
they use (``std_msgs``, ``geometry_msgs``) come from rosbags' ROS 2 Humble store.
"""

from __future__ import annotations

from functools import cache
from typing import Any

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from fuzzoff.events import Event
from fuzzoff.formats.mavros.convert import TOPIC_KINDS, Handler, MavrosTopic
from fuzzoff.formats.mavros.mavros_msgs import mavros_typedefs
from fuzzoff.formats.typedefs import bounded
from fuzzoff.lean_dataclass import dataclass


@cache
def _store(msgtype: str, embedded: str | None) -> Typestore:
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register({k: v for k, v in mavros_typedefs().items() if k not in store.fielddefs})
    if embedded:
        try:
            typedefs = bounded(get_types_from_msg(embedded, msgtype))
            store.register({k: v for k, v in typedefs.items() if k not in store.fielddefs})
        except Exception:
            pass
    return store


@dataclass(slots=True)
class MavrosTopicDecoder:
    """Decodes one MAVROS connection and converts each message (same protocol as PX4's)."""

    topic: str
    msgtype: str
    split: MavrosTopic
    handler: Handler
    store: Typestore
    index: int = 0
    failed: int = 0
    first_failure: tuple[float, str] | None = None
    unusable: str | None = None

    @classmethod
    def make(
        cls, topic: str, msgtype: str, split: MavrosTopic, handler: Handler, embedded: str | None
    ) -> MavrosTopicDecoder:
        return cls(topic, msgtype, split, handler, _store(msgtype, embedded))

    @property
    def message(self) -> str:
        return self.msgtype.rpartition("/")[2]

    @property
    def vehicle(self) -> str:
        return self.split.namespace

    @property
    def kind(self) -> str:
        return TOPIC_KINDS[self.split.name]

    def event(self, raw: bytes | memoryview, t: float) -> Event | None:
        index = self.index
        self.index = index + 1
        try:
            msg: Any = self.store.deserialize_cdr(raw, self.msgtype)
        except Exception as exc:
            self.failed += 1
            if self.first_failure is None:
                self.first_failure = (t, f"payload cannot be decoded ({exc})")
            return None
        # MAVROS sends at most one MAVLink message per ROS message (pairs: on the second).
        return self.handler(msg, t, index)
