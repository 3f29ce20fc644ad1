"""The mavros_msgs definitions fuzzoff needs, shipped as data (formats.md section 3).

ROS 1 bags and MCAP files embed their message definitions; ROS 2 ``.db3`` bags from Humble and
older do not, so a MAVROS bag of that age can only be decoded with definitions from elsewhere.
The ``.msg`` files here carry the fields and constants of MAVROS 2.12 (identical in MAVROS 1
for these types), without comments; their order is kept, so ROS 1 MD5 sums match the originals.
"""

from __future__ import annotations

from functools import cache
from importlib import resources
from typing import Any

MAVROS_TYPES: tuple[str, ...] = (
    "PositionTarget",
    "GlobalPositionTarget",
    "AttitudeTarget",
    "State",
    "Thrust",
    "ExtendedState",
)


def msg_text(name: str) -> str:
    """The ``.msg`` text of ``mavros_msgs/msg/<name>``."""
    return resources.files(__package__).joinpath(f"{name}.msg").read_text(encoding="utf-8")


@cache
def mavros_typedefs() -> dict[str, Any]:
    """rosbags type definitions for the shipped types, ready for ``Typestore.register``.

    Names are ``mavros_msgs/msg/<Type>``; nested standard types (``std_msgs/Header``,
    ``geometry_msgs/...``) must come from the typestore they are registered into.
    """
    from rosbags.typesys import get_types_from_msg

    types: dict[str, Any] = {}
    for name in MAVROS_TYPES:
        types.update(get_types_from_msg(msg_text(name), f"mavros_msgs/msg/{name}"))
    return types


__all__ = ["MAVROS_TYPES", "mavros_typedefs", "msg_text"]
