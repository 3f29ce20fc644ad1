"""Commands PX4's Commander always answers with a ``vehicle_command_ack`` (``COMMAND_ACK``).

Commander (``src/modules/commander/Commander.cpp``, ``Commander::handle_command`` at v1.14.4
to main) answers every command it handles, accepted or not, and it handles these on every
release fuzzoff models; the ROS 2 bridge forwards ``vehicle_command_ack`` on
``/fmu/out/vehicle_command_ack`` and the MAVLink receiver as ``COMMAND_ACK``. Seen on SITL
(corpora/ros2bridge, corpora/sitl): one ack each for DO_SET_MODE, COMPONENT_ARM_DISARM and
NAV_LAND on 1.16.2 and the 1.18 head. A command PX4 passes to another module (a camera, a
gimbal, a mission item) may be answered by it or not, so it is not listed.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from fuzzoff.releases import Release

ALWAYS_ANSWERED: Mapping[int, str] = MappingProxyType(
    {
        20: "NAV_RETURN_TO_LAUNCH",
        21: "NAV_LAND",
        22: "NAV_TAKEOFF",
        176: "DO_SET_MODE",
        400: "COMPONENT_ARM_DISARM",
    }
)
"""Command id -> name: the commands Commander answers on every modelled release."""


def always_answered(release: Release) -> Mapping[int, str]:
    """The commands PX4 of ``release`` always answers (the same on every release so far:
    a release that changes it gets a field of its record)."""
    del release
    return ALWAYS_ANSWERED


def command_name(command: int) -> str:
    """``NAV_LAND (21)`` for a listed command, ``command 31000`` for another."""
    name = ALWAYS_ANSWERED.get(command)
    return f"{name} ({command})" if name else f"command {command}"
