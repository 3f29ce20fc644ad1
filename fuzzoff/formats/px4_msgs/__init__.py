"""Bundled px4_msgs definitions, one ``.msg`` file per message per release (formats.md 2.2, 3).

Each folder (``1.13`` ... ``1.17``, ``main`` = release/1.18; a release names its folder in
``fuzzoff/releases.py``, ``Release.msg_folder``) holds the wire fields of the messages
fuzzoff decodes, in the order of that release's ``px4_msgs`` branch, with comments and constants
dropped except ``MESSAGE_VERSION`` (which names the ``_vN`` topic suffix; it is not on the wire).
They are used for recordings without embedded definitions (Humble-and-older ``.db3`` bags), by
the ROS 2 writers, and for the layouts the ULog writer declares (``ulog_fields``).
See ``docs/ros2.md`` for what is exact and what is not.
"""

from __future__ import annotations

import re
from functools import cache
from importlib import resources
from typing import Any

from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from fuzzoff import releases
from fuzzoff.formats.typedefs import bounded
from fuzzoff.profiles import ProfileError, px4_profile_for

PACKAGE = "px4_msgs"
_VERSION = re.compile(r"^\s*uint32\s+MESSAGE_VERSION\s*=\s*(\d+)", re.MULTILINE)


def type_name(message: str) -> str:
    """``TrajectorySetpoint`` -> ``px4_msgs/msg/TrajectorySetpoint``."""
    return f"{PACKAGE}/msg/{message}"


def release_for(px4: str | None) -> str | None:
    """The bundled folder for a ``--px4`` value (``1.15.4``, ``main``); None if none applies."""
    if not px4:
        return None
    try:
        profile = px4_profile_for(px4)
    except ProfileError:
        return None
    return releases.get(profile).msg_folder


def folders() -> tuple[str, ...]:
    """The bundled folders, oldest first (the release records' ``msg_folder``, once each)."""
    out: list[str] = []
    for release in releases.RELEASES:
        if release.msg_folder is not None and release.msg_folder not in out:
            out.append(release.msg_folder)
    return tuple(out)


def first_release_of(folder: str) -> str:
    """The oldest release whose messages ``folder`` holds: the release a recording fitting only
    that folder is called (``main`` holds 1.18's layouts: a bag of the 1.18 head is 1.18, as
    its ULog says; main's own bags cannot be told from it by their messages)."""
    for release in releases.RELEASES:
        if release.msg_folder == folder:
            return release.name
    return folder


SEPARATOR = "=" * 80
"""Between a message's definition and those of the px4_msgs types it nests, as ROS 2 embeds
them (MCAP ``ros2msg`` schemas, rosbag2 ``message_definitions``)."""
_NESTED = re.compile(r"^([A-Z][A-Za-z0-9]*)(?:\[\d*\])?\s", re.MULTILINE)


@cache
def definition(release: str, message: str) -> str | None:
    """The ``.msg`` text of ``message`` in ``release``, or None where that release lacks it.

    A message that nests other px4_msgs types (``ArmingCheckReply`` holds ``Event[5]``) comes
    with their definitions after it, each under a ``MSG: px4_msgs/<Type>`` line, as ROS 2
    embeds a definition: one text that a type store registers whole."""
    text = _own(release, message)
    if text is None:
        return None
    nested = [(name, _own(release, name)) for name in dict.fromkeys(_NESTED.findall(text))]
    return text + "".join(
        f"{SEPARATOR}\nMSG: {PACKAGE}/{name}\n{body}" for name, body in nested if body is not None
    )


def own_part(text: str) -> str:
    """The message's own part of a ``definition`` (without the nested types after it)."""
    return text.split(SEPARATOR, 1)[0]


def _own(release: str, message: str) -> str | None:
    node = resources.files(__name__).joinpath(release, f"{message}.msg")
    if not node.is_file():
        return None
    return node.read_text(encoding="utf-8")


def releases_with(message: str) -> list[str]:
    """The releases (oldest first) that define ``message``."""
    return [r for r in folders() if definition(r, message) is not None]


def message_version(text: str) -> int:
    """``MESSAGE_VERSION`` of a definition (0 when it has none)."""
    match = _VERSION.search(own_part(text))
    return int(match.group(1)) if match else 0


def declares_version(text: str) -> bool:
    """Does the definition declare ``MESSAGE_VERSION`` (PX4 1.16+ on versioned messages)?"""
    return _VERSION.search(own_part(text)) is not None


@cache
def typestore_for(typename: str, text: str) -> Typestore:
    """A rosbags type store holding ``typename`` as ``text`` defines it (one per definition).

    One store per definition text, because two connections may carry the same type name with
    different definitions (formats.md 3: the per-connection choice AnyReader does not make).
    """
    store = get_typestore(Stores.EMPTY)
    store.register(bounded(get_types_from_msg(text, typename)))
    return store


def field_names(typename: str, text: str) -> frozenset[str]:
    """The wire field names of ``typename`` under ``text``."""
    store = typestore_for(typename, text)
    return frozenset(name for name, _ in store.fielddefs[typename][1])


_C_TYPES: dict[str, tuple[str, int]] = {
    "uint64": ("uint64_t", 8),
    "int64": ("int64_t", 8),
    "float64": ("double", 8),
    "uint32": ("uint32_t", 4),
    "int32": ("int32_t", 4),
    "float32": ("float", 4),
    "uint16": ("uint16_t", 2),
    "int16": ("int16_t", 2),
    "uint8": ("uint8_t", 1),
    "int8": ("int8_t", 1),
    "byte": ("uint8_t", 1),
    "char": ("char", 1),
    "bool": ("bool", 1),
}
"""ROS 2 base type -> (uORB C type, size in bytes)."""


@cache
def ulog_fields(release: str, message: str) -> tuple[str, ...] | None:
    """``message``'s fields as PX4 ``release`` logs them in a ULog format record, or None where
    the release lacks it or a field is not a number (nested types are not derived).

    PX4's uORB generator orders the ``.msg`` fields by type size, largest first (in file
    order among equals), and pads the struct to 8 bytes with ``uint8_t[N] _padding0``; the
    ULogs PX4 SITL 1.14 to 1.18 writes declare exactly that."""
    text = definition(release, message)
    if text is None:
        return None
    typename = type_name(message)
    fields: list[tuple[int, str]] = []
    total = 0
    field_defs: list[tuple[str, Any]] = typestore_for(typename, text).fielddefs[typename][1]
    for name, (nodetype, details) in field_defs:
        count: int | None = None
        if nodetype == Nodetype.ARRAY:
            (nodetype, details), count = details
        base = details[0]
        if nodetype != Nodetype.BASE or base not in _C_TYPES:
            return None
        c_type, size = _C_TYPES[base]
        fields.append((size, f"{c_type} {name}" if count is None else f"{c_type}[{count}] {name}"))
        total += size * (count or 1)
    fields.sort(key=lambda field: -field[0])  # stable: file order among equal sizes
    padding = -total % 8
    return tuple(text for _, text in fields) + (
        (f"uint8_t[{padding}] _padding0",) if padding else ()
    )
