"""Load a ULog with pyulog and say what could not be read, and where (formats.md 8.2, 8.3, 9).

pyulog 1.3 falls short for a linter in three ways, wrapped here without re-parsing the file:

* it reports damage only as a ``file_corruption`` flag and a ``print`` on stdout, with no position;
* it stops silently at a message cut in half (a truncated log looks complete);
* it prints diagnostics on stdout, which would corrupt ``--format json``.

``_TrackedULog`` observes pyulog's own reading instead: the 3-byte record headers it decodes (a
running end offset per section, which gives the truncation point) and the moment it first sets its
corruption flag (with the last good timestamp). Both hooks are on pyulog's existing per-record
calls, so the load costs the same as pyulog's own. Pinned to pyulog 1.3 (private attributes).
"""

from __future__ import annotations

import contextlib
import io
import os
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pyulog import ULog
from pyulog.core import ULogException

from fuzzoff.sources.base import SourceError, SourceProblem

_unpack_header = struct.Struct("<HB").unpack


class _Header:
    """Stands in for ``ULog._MessageHeader``; also keeps the end offset of the records read."""

    __slots__ = ("end", "msg_size", "msg_type", "partial")

    def __init__(self, start: int) -> None:
        self.msg_size = 0
        self.msg_type = 0
        self.end = start
        self.partial = False

    def initialize(self, data: bytes) -> None:
        try:
            self.msg_size, self.msg_type = _unpack_header(data)
        except struct.error:
            self.partial = len(data) > 0  # 1 or 2 bytes: the file ends inside a record header
            raise
        self.end += 3 + self.msg_size


@dataclass(slots=True)
class _Corruption:
    section: str
    offset: int
    last_timestamp: int


class _TrackedULog(ULog):  # type: ignore[misc]
    """pyulog's ``ULog``, observed (see the module docstring)."""

    def __init__(self, path: str, topics: Sequence[str] | None, header_only: bool) -> None:
        self._headers: list[tuple[str, _Header]] = []
        self._section = "definitions"
        self._corruption: _Corruption | None = None
        self.missing_formats: list[str] = []
        self.missing_format_offset: int | None = None
        self._MessageHeader = self._new_header
        self._MessageAddLogged = self._add_logged
        super().__init__(
            path,
            message_name_filter_list=list(topics) if topics is not None else None,
            disable_str_exceptions=True,
            parse_header_only=header_only,
        )

    # pyulog assigns ``self._file_corrupt``; a property sees the first time it becomes true.
    @property
    def _file_corrupt(self) -> bool:
        return self._corruption is not None

    @_file_corrupt.setter
    def _file_corrupt(self, value: bool) -> None:
        if value and self._corruption is None:
            offset = self._headers[-1][1].end if self._headers else 16
            last = getattr(self, "_last_timestamp", 0)
            self._corruption = _Corruption(self._section, offset, last)

    def _new_header(self) -> _Header:
        handle = getattr(self, "_file_handle", None)
        start = handle.tell() if handle is not None else 16
        header = _Header(start)
        self._headers.append((self._section, header))
        return header

    def _add_logged(self, data: bytes, header: Any, formats: dict[str, Any]) -> Any:
        try:
            return ULog._MessageAddLogged(data, header, formats)
        except KeyError:
            name = ULog.parse_string(data[3:])
            if self.missing_format_offset is None and self._headers:
                header = self._headers[-1][1]
                self.missing_format_offset = header.end - 3 - header.msg_size
            if name not in self.missing_formats:
                self.missing_formats.append(name)
            raise

    def _read_file_data(self, message_name_filter_list: Any, read_until: Any = None) -> None:
        self._section = "data"
        super()._read_file_data(message_name_filter_list, read_until)

    @property
    def corruption(self) -> _Corruption | None:
        return self._corruption

    def last_header(self, section: str) -> _Header | None:
        for name, header in reversed(self._headers):
            if name == section:
                return header
        return None


@dataclass(slots=True)
class Loaded:
    """A loaded ULog and what could not be read."""

    ulog: Any
    problems: list[SourceProblem] = field(default_factory=list)
    library_output: list[str] = field(default_factory=list)
    size: int = 0


def load(
    path: Path,
    topics: Sequence[str] | None,
    *,
    header_only: bool = False,
    seconds: Callable[[int], float] | None = None,
) -> Loaded:
    """Read ``path`` with pyulog (only ``topics``; all when None). Raises ``SourceError`` when
    the file is not a readable ULog at all; damage after the header becomes ``problems``."""
    try:
        size = os.path.getsize(path)
    except OSError as exc:
        raise SourceError(path, f"cannot open: {exc.strerror or exc}") from None
    captured = io.StringIO()
    try:
        with contextlib.redirect_stdout(captured):
            ulog = _TrackedULog(str(path), topics, header_only)
    except ULogException as exc:
        raise SourceError(path, f"not a readable ULog: {_reason(exc)}", "byte 0") from None
    except OSError as exc:
        raise SourceError(path, f"cannot read: {exc.strerror or exc}") from None
    except (MemoryError, RecursionError, ValueError, TypeError, KeyError, IndexError) as exc:
        # pyulog raised where it usually records corruption: nothing usable came out.
        raise SourceError(path, f"pyulog could not read it ({type(exc).__name__}: {exc})") from None
    output = [line for line in captured.getvalue().splitlines() if line.strip()]
    loaded = Loaded(ulog, library_output=output, size=size)
    to_s = seconds or (lambda ts: (ts - ulog.start_timestamp) / 1e6)
    loaded.problems.extend(_problems(ulog, size, header_only, to_s))
    return loaded


def _reason(exc: Exception) -> str:
    text = str(exc)
    if "too short" in text:
        return "shorter than the 16-byte ULog header"
    if "incompatible" in text.lower():
        return "it sets an incompatible-feature flag this reader does not know"
    if "header" in text.lower():
        return "no ULog header (wrong magic bytes)"
    return text


def _problems(
    ulog: _TrackedULog, size: int, header_only: bool, to_s: Callable[[int], float]
) -> list[SourceProblem]:
    """At most one problem: the first thing that went wrong (later damage follows from it)."""
    definitions = ulog.last_header("definitions")
    if definitions is not None and (definitions.partial or definitions.end > size):
        return [SourceProblem("truncated in the definition section", f"byte {size}")]
    corruption = ulog.corruption
    if corruption is not None and corruption.section == "definitions":
        what = "broken definition section (formats, info or parameters unreadable)"
        return [SourceProblem(what, f"byte {corruption.offset}")]
    if ulog.missing_formats:
        names = ", ".join(ulog.missing_formats[:3])
        more = f" and {len(ulog.missing_formats) - 3} more" if len(ulog.missing_formats) > 3 else ""
        what = (
            f"broken definition section: no message format for topic {names}{more} "
            "(its data cannot be decoded)"
        )
        where = f"byte {ulog.missing_format_offset} (the topic's subscription record)"
        return [SourceProblem(what, where)]
    if corruption is not None:
        t = to_s(corruption.last_timestamp) if corruption.last_timestamp else None
        after = f", after the last good message at {t:.3f} s" if t is not None else ""
        what = "corrupt data: damaged records were skipped and reading resumed after them"
        return [SourceProblem(what, f"byte {corruption.offset}{after}", time_s=t)]
    data = ulog.last_header("data")
    if header_only or data is None or not (data.partial or data.end > size):
        return []
    good_end = data.end if data.partial else data.end - 3 - data.msg_size
    last = ulog.last_timestamp
    t = to_s(last) if last else None
    after = f" (the last complete message is at {t:.3f} s)" if t is not None else ""
    if not data.partial and _implausible(data):
        what = (
            f"corrupt record header: it declares {data.msg_size} bytes of type "
            f"{data.msg_type}, more than the rest of the file; nothing after it was read"
        )
    else:
        what = f"truncated in the middle of a message ({size - good_end} bytes left over)"
    return [SourceProblem(what, f"byte {good_end}{after}", time_s=t)]


_RECORD_TYPES = frozenset(b"FDIMPQARSOLCB")
"""ULog record types pyulog knows (formats.md 8)."""


def _implausible(header: _Header) -> bool:
    """A record header no logger writes: unknown type or a size beyond pyulog's own limit."""
    return header.msg_type not in _RECORD_TYPES or header.msg_size > 10000
