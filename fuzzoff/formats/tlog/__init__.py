"""MAVLink telemetry logs (.tlog): reader, packet framing and writer."""

from __future__ import annotations

from pathlib import Path

from fuzzoff.formats.format import Format


def _detect(path: Path, head: bytes) -> str | None:
    """No header: a record's first packet starts after its 8-byte timestamp (MAVLink 1 or 2)."""
    return "tlog" if len(head) >= 9 and head[8] in (0xFD, 0xFE) else None


FORMAT = Format(
    name="tlog",
    reader="fuzzoff.formats.tlog.reader:TlogSource",
    writer="fuzzoff.formats.tlog.writer:write_tlog",
    clock="fuzzoff.formats.tlog.clock:start_s",
    detect_file=_detect,
    names=("tlog",),
    suffixes=(".tlog",),
    written_suffix=".tlog",
    fallback=True,
    transports=("mavlink",),
)
