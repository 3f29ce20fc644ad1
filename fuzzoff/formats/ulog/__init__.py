"""PX4 ULogs: reader (pyulog), the damage checks around it, topic decoders and writer."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from fuzzoff.formats.format import Format

MAGIC = b"ULog\x01\x12\x35"


def _detect(path: Path, head: bytes) -> str | None:
    return "ulog" if head.startswith(MAGIC) else None


def _options(px4: str | None) -> Mapping[str, Any]:
    return {"px4_version": px4} if px4 else {}


FORMAT = Format(
    name="ulog",
    reader="fuzzoff.formats.ulog.reader:UlogSource",
    writer="fuzzoff.formats.ulog.writer:write_ulog",
    clock="fuzzoff.formats.ulog.clock:start_s",
    detect_file=_detect,
    names=("ulog",),
    suffixes=(".ulg",),
    written_suffix=".ulg",
    writer_options=_options,
)
