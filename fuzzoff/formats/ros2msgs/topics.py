"""PX4 uXRCE-DDS and microRTPS topic names (formats.md 2.1): namespace, direction, message.

``/px4_1/fmu/in/vehicle_attitude_setpoint_v1`` -> namespace ``/px4_1``, direction ``in``, name
``vehicle_attitude_setpoint``, version 1; v1.13's ``/fmu/trajectory_setpoint/in`` is the same
with no version. A namespace is the vehicle: ``""`` for none.
"""

from __future__ import annotations

import re

from fuzzoff.formats.uorb import TOPICS
from fuzzoff.lean_dataclass import dataclass

_UXRCE = re.compile(r"^(?P<ns>/.+?)?/fmu/(?P<dir>in|out)/(?P<name>[a-z0-9_]+?)(?:_v(?P<ver>\d+))?$")
_RTPS = re.compile(r"^(?P<ns>/.+?)?/fmu/(?P<name>[a-z0-9_]+?)/(?P<dir>in|out)$")

MESSAGE_FOR_NAME: dict[str, str] = {
    name: topic.message for name, topic in TOPICS.items() if topic.message is not None
}
"""Topic base name -> px4_msgs message: the topics fuzzoff decodes."""

NAME_FOR_MESSAGE: dict[str, str] = {}
for _name, _msg in MESSAGE_FOR_NAME.items():
    NAME_FOR_MESSAGE.setdefault(_msg, _name)

OUTPUT_MESSAGES = frozenset(
    topic.message for topic in TOPICS.values() if topic.message is not None and topic.published
)
"""Messages PX4 publishes (``/fmu/out``); the rest are inputs to PX4."""


@dataclass(frozen=True, slots=True)
class TopicRef:
    """What a PX4 topic name says."""

    namespace: str
    direction: str
    name: str
    version: int | None
    legacy: bool = False
    """The v1.13 ``/fmu/<name>/in|out`` form."""


def parse_topic(topic: str) -> TopicRef | None:
    """Split a PX4 topic name; None for anything else. A missing leading slash is tolerated."""
    if not topic.startswith("/"):
        topic = "/" + topic
    match = _UXRCE.match(topic)
    if match is not None:
        ver = match.group("ver")
        return TopicRef(
            match.group("ns") or "",
            match.group("dir"),
            match.group("name"),
            int(ver) if ver is not None else None,
        )
    match = _RTPS.match(topic)
    if match is not None:
        return TopicRef(
            match.group("ns") or "", match.group("dir"), match.group("name"), None, True
        )
    return None


def namespace_of(topic: str) -> str:
    """The part before ``/fmu/`` (a remapped topic without ``/fmu/`` belongs to vehicle ``""``)."""
    ref = parse_topic(topic)
    if ref is not None:
        return ref.namespace
    head, sep, _ = topic.partition("/fmu/")
    return head if sep else ""


def topic_for(message: str, namespace: str = "", version: int = 0, legacy: bool = False) -> str:
    """The topic PX4 uses for ``message`` (inverse of ``parse_topic``)."""
    name = NAME_FOR_MESSAGE[message]
    direction = "out" if message in OUTPUT_MESSAGES else "in"
    if legacy:
        return f"{namespace}/fmu/{name}/{direction}"
    suffix = f"_v{version}" if version > 0 else ""
    return f"{namespace}/fmu/{direction}/{name}{suffix}"
