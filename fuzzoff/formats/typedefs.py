"""Message definitions read from a recording, checked before rosbags builds decoders for them.

rosbags generates a decoder's code with one statement per element of a fixed-size array of
strings or messages (``string[100000] s``): a one-line definition in a damaged or hostile file
then costs gigabytes and minutes before the first message (about 40 kB an element). Arrays of
numbers are read in one step whatever their size, so only the unrolled elements are counted.
"""

from __future__ import annotations

from typing import Any

from rosbags.interfaces import Nodetype

MAX_UNROLLED = 1024
"""Most unrolled elements one definition may declare; px4_msgs and mavros_msgs need a few."""


def bounded(types: dict[str, Any]) -> dict[str, Any]:
    """``types`` (rosbags' parsed definitions) when every type's decoder stays small, else a
    ``ValueError`` saying which type declares too much."""
    memo: dict[str, int] = {}
    for name in types:
        count = _unrolled(name, types, memo, depth=0)
        if count > MAX_UNROLLED:
            short = name.rsplit("/", 1)[-1]
            raise ValueError(
                f"{count} string or message array elements in {short} (limit {MAX_UNROLLED})"
            )
    return types


def _unrolled(name: str, types: dict[str, Any], memo: dict[str, int], depth: int) -> int:
    if name in memo:
        return memo[name]
    if depth > 32 or name not in types:  # a cycle or a type from elsewhere: rosbags decides
        return 0
    memo[name] = MAX_UNROLLED + 1  # a type that contains itself is refused
    total = sum(_field_cost(desc, types, memo, depth) for _, desc in types[name][1])
    memo[name] = total
    return total


def _field_cost(desc: Any, types: dict[str, Any], memo: dict[str, int], depth: int) -> int:
    node, detail = desc
    if node == Nodetype.NAME:
        return _unrolled(detail, types, memo, depth + 1)
    if node == Nodetype.ARRAY:
        (sub_node, sub_detail), length = detail
        if sub_node == Nodetype.BASE and sub_detail[0] != "string":
            return 0  # numbers: one read for the whole array
        inner = _field_cost((sub_node, sub_detail), types, memo, depth)
        return int(length) * (1 + inner)
    if node == Nodetype.SEQUENCE:
        (sub_node, sub_detail), _ = detail
        return _field_cost((sub_node, sub_detail), types, memo, depth)
    return 0
