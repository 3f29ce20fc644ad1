"""px4_msgs types on DDS through the ``cyclonedds`` package: types, writers, raw readers.

A type is a cyclonedds ``IdlStruct`` built from the release's ``.msg`` fields (read with
rosbags' parser), named as the ROS 2 middleware names it, so that the agent's Fast-DDS matches
it with PX4's topics. Samples are written in XCDR1 (``DataRepresentation`` CDR v0), the
encoding ROS 2 and the agent use. A reader hands back each sample's bytes as they arrived
(encapsulation header included), which is what a bag stores: cyclonedds' ``DataReader.take``
deserializes, so the bytes come from its C layer's take (``ddspy_take``), as ``take`` itself
gets them.
"""

from __future__ import annotations

import dataclasses
import time
import types
from collections.abc import Callable
from functools import cache
from typing import Any

from cyclonedds._clayer import ddspy_take
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as idl
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from rosbags.interfaces import (
    Nodetype,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.interfaces import Qos as BagQos

from fuzzoff.formats import px4_msgs
from fuzzoff.sitl.ros2.names import BridgeTopic

_BASE: dict[str, Any] = {
    "bool": bool,
    "byte": idl.uint8,
    "char": idl.uint8,
    "uint8": idl.uint8,
    "int8": idl.int8,
    "uint16": idl.uint16,
    "int16": idl.int16,
    "uint32": idl.uint32,
    "int32": idl.int32,
    "uint64": idl.uint64,
    "int64": idl.int64,
    "float32": idl.float32,
    "float64": idl.float64,
}
_ARRAY: Any = idl.array
"""cyclonedds' fixed-size array annotation (``array[float32, 3]``)."""
_XCDR1 = Policy.DataRepresentation(use_cdrv0_representation=True)
DDS_INFINITE_NS = 0x7FFFFFFFFFFFFFFF
ROS_INFINITE = QosTime(2147483647, 4294967295)
"""How rosbag2's metadata writes an infinite duration."""

EXAMPLE_PUBLISHER = Qos(
    Policy.Reliability.Reliable(max_blocking_time=100_000_000),
    Policy.Durability.Volatile,
    Policy.History.KeepLast(10),
    _XCDR1,
)
"""rclcpp's ``create_publisher(topic, 10)``: reliable, volatile, keep last 10."""
RECORDER_READER = Qos(
    Policy.Reliability.BestEffort,
    Policy.Durability.Volatile,
    Policy.History.KeepLast(100),
    _XCDR1,
)
"""A best-effort reader matches every writer, PX4's best-effort ones included."""


def _zero(base: str) -> Any:
    return False if base == "bool" else 0.0 if base.startswith("float") else 0


@cache
def _layout(topic: BridgeTopic) -> tuple[dict[str, Any], dict[str, Any]]:
    """The fields' cyclonedds types and their zero values (as a C++ message starts)."""
    store = px4_msgs.typestore_for(topic.ros_type, topic.msgdef)
    return _fields(store, topic.ros_type)


def _fields(store: Any, typename: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """``typename``'s fields in ``store``: numbers, fixed arrays of numbers, and px4_msgs
    types nested in it (``ArmingCheckReply.events``, an array of ``Event``)."""
    fields: dict[str, Any] = {}
    zeros: dict[str, Any] = {}
    field_defs: list[tuple[str, Any]] = store.fielddefs[typename][1]
    for name, (nodetype, details) in field_defs:
        if nodetype == Nodetype.ARRAY:
            (inner_type, inner), count = details
            if inner_type == Nodetype.NAME:
                nested, zero = _nested(store, inner)
                fields[name] = _ARRAY[nested, count]
                zeros[name] = [zero] * count
                continue
            if inner_type != Nodetype.BASE:
                raise TypeError(f"{typename}.{name}: only arrays of numbers are supported")
            fields[name] = _ARRAY[_BASE[inner[0]], count]
            zeros[name] = [_zero(inner[0])] * count
        elif nodetype == Nodetype.BASE:
            fields[name] = _BASE[details[0]]
            zeros[name] = _zero(details[0])
        elif nodetype == Nodetype.NAME:
            fields[name], zeros[name] = _nested(store, details)
        else:
            raise TypeError(f"{typename}.{name}: sequence fields are not supported")
    return fields, zeros


def _nested(store: Any, typename: str) -> tuple[Any, Any]:
    """A nested px4_msgs type as a cyclonedds struct (named as the middleware names it), and
    its zero value."""
    fields, zeros = _fields(store, typename)
    message = typename.rsplit("/", 1)[-1]
    cls = _struct(message, f"px4_msgs::msg::dds_::{message}_", fields)
    return cls, cls(**zeros)


def _struct(message: str, dds_type: str, fields: dict[str, Any]) -> Any:
    cls = types.new_class(
        message + "_",
        (IdlStruct,),
        {"typename": dds_type},
        lambda ns: ns.update({"__annotations__": fields}),
    )
    return dataclasses.dataclass(cls)  # noqa: TID251 (cyclonedds reads the standard one's fields)


@cache
def idl_type(topic: BridgeTopic) -> Any:
    """The cyclonedds type of ``topic``'s message (one class per definition)."""
    fields, _ = _layout(topic)
    return _struct(topic.message, topic.dds_type, fields)


def zero_sample(topic: BridgeTopic, **values: Any) -> Any:
    """A sample with every field zero (as a C++ message is built) except ``values``."""
    _, zeros = _layout(topic)
    unknown = set(values) - set(zeros)
    if unknown:
        raise TypeError(f"{topic.message} has no field {', '.join(sorted(unknown))}")
    return idl_type(topic)(**{**zeros, **values})


class Publisher:
    """A DDS writer of one bridge topic, with the QoS of the example's publishers."""

    def __init__(self, participant: DomainParticipant, topic: BridgeTopic) -> None:
        self.topic = topic
        self._writer = DataWriter(
            participant, Topic(participant, topic.dds_topic, idl_type(topic)), EXAMPLE_PUBLISHER
        )

    def publish(self, **values: Any) -> None:
        self._writer.write(zero_sample(self.topic, **values))

    def write(self, sample: Any) -> None:
        """A sample of this topic's type as it is (a replayed message)."""
        self._writer.write(sample)

    def matched(self) -> int:
        """How many readers this writer has matched (DDS discovery)."""
        return len(self._writer.get_matched_subscriptions())


Received = Callable[[BridgeTopic, bytes, int], None]
"""(topic, the sample's bytes, receive time in ns since the epoch)"""


class RawReader:
    """A DDS reader of one bridge topic that keeps each sample's bytes."""

    def __init__(self, participant: DomainParticipant, topic: BridgeTopic) -> None:
        self.topic = topic
        self.reader = DataReader(
            participant, Topic(participant, topic.dds_topic, idl_type(topic)), RECORDER_READER
        )
        self.offered: dict[int, BagQos] = {}

    def take(self, deliver: Received) -> int:
        """Hand every waiting sample to ``deliver``, stamped now; how many there were."""
        samples = ddspy_take(self.reader._ref, 0xFFFF, 256)
        if isinstance(samples, int) or not samples:
            return 0
        now = time.time_ns()
        count = 0
        for data, info in samples:
            if info.valid_data:
                deliver(self.topic, bytes(data), now)
                count += 1
        if count:
            self._learn_writers()
        return count

    def decode(self, data: bytes) -> Any:
        return idl_type(self.topic).deserialize(data)

    def _learn_writers(self) -> None:
        handles = self.reader.get_matched_publications()
        if len(handles) == len(self.offered):
            return
        for handle in handles:
            if handle not in self.offered:
                endpoint = self.reader.get_matched_publication_data(handle)
                if endpoint is not None:
                    self.offered[handle] = bag_qos(endpoint.qos)


def _duration(policy: Any, attribute: str) -> QosTime:
    ns = int(getattr(policy, attribute)) if policy is not None else DDS_INFINITE_NS
    if ns >= DDS_INFINITE_NS:
        return ROS_INFINITE
    return QosTime(ns // 1_000_000_000, ns % 1_000_000_000)


def bag_qos(qos: Qos) -> BagQos:
    """A writer's QoS as discovered, in rosbag2's terms: a remote writer's history is not
    announced, so it is unknown with depth 0, as ``ros2 bag record`` writes it."""
    reliability = qos[Policy.Reliability.BestEffort]
    durability = qos[Policy.Durability.Volatile]
    liveliness = qos[Policy.Liveliness.Automatic]
    return BagQos(
        history=QosHistory.UNKNOWN,
        depth=0,
        reliability=(
            QosReliability.BEST_EFFORT
            if reliability == Policy.Reliability.BestEffort
            else QosReliability.RELIABLE
        ),
        durability=(
            QosDurability.TRANSIENT_LOCAL
            if durability == Policy.Durability.TransientLocal
            else QosDurability.VOLATILE
        ),
        deadline=_duration(qos[Policy.Deadline], "deadline"),
        lifespan=_duration(qos[Policy.Lifespan], "lifespan"),
        liveliness=(
            QosLiveliness.MANUAL_BY_TOPIC
            if isinstance(liveliness, Policy.Liveliness.ManualByTopic)
            else QosLiveliness.AUTOMATIC
        ),
        liveliness_lease_duration=_duration(liveliness, "lease_duration"),
        avoid_ros_namespace_conventions=False,
    )
