"""The names PX4's bridge gives a release's topics and types on DDS (no DDS import here).

A ROS 2 topic ``/fmu/in/trajectory_setpoint`` is the DDS topic ``rt/fmu/in/trajectory_setpoint``
and ``px4_msgs/msg/TrajectorySetpoint`` the DDS type ``px4_msgs::msg::dds_::TrajectorySetpoint_``
(the ROS 2 middleware's mangling); a message whose ``MESSAGE_VERSION`` is N > 0 has the topic
suffix ``_vN`` (PX4's ``src/modules/uxrce_dds_client/dds_topics.yaml`` of the release).
"""

from __future__ import annotations

from fuzzoff.formats import px4_msgs
from fuzzoff.formats.ros2msgs.topics import topic_for
from fuzzoff.lean_dataclass import dataclass

SENT = ("OffboardControlMode", "TrajectorySetpoint", "VehicleCommand")
"""What px4_ros_com's offboard_control example publishes."""
RECEIVED = (
    "VehicleStatus",
    "VehicleCommandAck",
    "VehicleControlMode",
    "FailsafeFlags",
    "VehicleLocalPosition",
    "VehicleLandDetected",
)
"""PX4's outputs a recording of the flight keeps (those fuzzoff reads; the land detector says
whether PX4 takes a plain disarm, as EXTENDED_SYS_STATE does over MAVLink: issue 33's airplane
rolling on the ground counts as flying)."""


class NamesError(Exception):
    """A release or message with no bundled definition."""


@dataclass(frozen=True, slots=True)
class BridgeTopic:
    """One px4_msgs message as the bridge of one release carries it."""

    message: str
    """``TrajectorySetpoint``"""
    ros_topic: str
    """``/fmu/in/trajectory_setpoint``"""
    msgdef: str
    """The release's ``.msg`` text (the bag's schema)."""

    @property
    def ros_type(self) -> str:
        return px4_msgs.type_name(self.message)

    @property
    def dds_topic(self) -> str:
        return "rt" + self.ros_topic

    @property
    def dds_type(self) -> str:
        return f"px4_msgs::msg::dds_::{self.message}_"


def msg_folder(release: str) -> str:
    """The bundled ``.msg`` folder of a PX4 release (``1.16.2`` -> ``1.16``; ``1.18.0``,
    the release/1.18 branch, -> ``main``)."""
    folder = px4_msgs.release_for(release)
    if folder is None:
        raise NamesError(f"PX4 {release}: no bundled px4_msgs definitions")
    return folder


def bridge_topic(release: str, message: str, namespace: str = "") -> BridgeTopic:
    folder = msg_folder(release)
    text = px4_msgs.definition(folder, message)
    if text is None:
        raise NamesError(f"PX4 {release} ({folder}): no {message}.msg")
    version = px4_msgs.message_version(text)
    return BridgeTopic(message, topic_for(message, namespace, version), text)
