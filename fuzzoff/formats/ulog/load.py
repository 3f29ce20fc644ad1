"""Load a ULog with pyulog and say what could not be read, and where (formats.md 8.2, 8.3, 9).

pyulog 1.3 falls short for a linter in four ways, wrapped here without re-parsing the file:

* it reports damage only as a ``file_corruption`` flag and a ``print`` on stdout, with no position;
* it stops silently at a message cut in half (a truncated log looks complete);
* it prints diagnostics on stdout, which would corrupt ``--format json``;
* in the definition section it can loop forever on a damaged record near the end of the file
  (``_DefinitionsHandle`` says how, and mends it).

``_TrackedULog`` observes pyulog's own reading instead: the 3-byte record headers it decodes (a
running end offset per section, which gives the truncation point) and the moment it first sets its
corruption flag (with the last good timestamp). Both hooks are on pyulog's existing per-record
calls, so the load costs the same as pyulog's own. Pinned to pyulog 1.3 (private attributes).

Two more gaps are closed on the same calls: a record whose payload is too short for its type (a
data record whose size field reads 0) makes pyulog stop reading as if the file had ended, so
such a record is made corruption, which pyulog skips; and a format record (``F``) whose text a
flipped byte damaged still parses, so each one is checked against the ULog grammar
(``_format_damage``) and the topics it describes are set aside.

A fifth gap is speed: pyulog's per-record loop runs over every record of the data section
whatever the filter. Given a reader's ``RowPlan``, ``_TrackedULog`` first walks the record framing
(``framing``) and hands pyulog only the records the reader will read; at anything unusual it
hands pyulog the file as it is, and ``load`` reads the file again without the plan whenever
pyulog's read of the framed records reports anything, so every problem above is found and
placed by the plain read.
"""

from __future__ import annotations

import contextlib
import io
import mmap
import os
import re
import struct
from collections.abc import Callable, Sequence
from dataclasses import field
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from pyulog import ULog
from pyulog.core import ULogException

from fuzzoff.formats.ulog.framing import LIMIT, Framed, RowPlan, frame
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.recording import SourceError, SourceProblem

_unpack_header = struct.Struct("<HB").unpack


_DATA = ord("D")


class _Header:
    """Stands in for ``ULog._MessageHeader``; also keeps the end offset of the records read,
    and arms ``data`` (the data record pyulog decodes next) for a payload too short to hold a
    message id (``_short_data``)."""

    __slots__ = ("data", "end", "first", "msg_size", "msg_type", "partial")

    def __init__(self, start: int) -> None:
        self.msg_size = 0
        self.msg_type = 0
        self.first = start
        self.end = start
        self.partial = False
        self.data: Any = None

    def initialize(self, data: bytes) -> None:
        try:
            self.msg_size, self.msg_type = size, kind = _unpack_header(data)
        except struct.error:
            self.partial = len(data) > 0  # 1 or 2 bytes: the file ends inside a record header
            raise
        self.end += 3 + size
        if size < 2 and kind == _DATA and self.data is not None:
            self.data.initialize = _short_data.__get__(self.data)

    @property
    def start(self) -> int:
        """Where the last record read begins (worked out, not stored: ``initialize`` runs once
        per record); the section's start before any."""
        return self.end - 3 - self.msg_size if self.end != self.first else self.first


@dataclass(slots=True)
class _Corruption:
    """Where pyulog first found damage: the record it was reading then."""

    section: str
    start: int
    end: int
    """Where the record ends by its header's size (past the file's end when it was cut)."""
    plausible: bool
    """A header a logger could have written (see ``_implausible``)."""
    partial: bool
    """The file ends inside the record's 3-byte header."""
    last_timestamp: int


class _DefinitionsHandle:
    """The file as pyulog reads its definition section.

    To step over a damaged record, pyulog seeks back relative to where it would be had its last
    read returned every byte it asked for; at the end of the file the read comes back short and
    the seek lands before the record's start, so the same records are read again and again,
    forever. Here a relative seek after a short read is taken from the position pyulog assumes,
    which is what it means: one byte past the damaged record's start. The data section checks
    for short reads itself and is read from the plain file (no cost per record)."""

    __slots__ = ("_assumed_end", "file")

    def __init__(self, file: BinaryIO) -> None:
        self.file = file
        self._assumed_end: int | None = None

    def read(self, size: int = -1) -> bytes:
        start = self.file.tell()
        data = self.file.read(size)
        self._assumed_end = start + size if 0 <= len(data) < size else None
        return data

    def seek(self, offset: int, whence: int = os.SEEK_SET) -> int:
        if whence == os.SEEK_CUR and self._assumed_end is not None:
            offset, whence = self._assumed_end + offset, os.SEEK_SET
        self._assumed_end = None
        return self.file.seek(offset, whence)

    def tell(self) -> int:
        return self.file.tell()

    def close(self) -> None:
        self.file.close()


def _whole(record: type[Any]) -> type[Any]:
    """pyulog's record class, raising ``ValueError`` where its payload is too short.

    pyulog decodes each record inside a handler for corruption (``ValueError`` among others),
    itself inside one for ``struct.error``, which it takes for the end of the file. A record too
    short for its type (a size field damaged to 0) raised ``struct.error``: the rest of the file
    was dropped in silence. As ``ValueError`` it is what it is: a damaged record, skipped."""

    class Whole(record):  # type: ignore[misc]
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            try:
                super().__init__(*args, **kwargs)
            except struct.error as exc:
                raise ValueError(f"record too short ({exc})") from None

    Whole.__name__ = Whole.__qualname__ = record.__name__
    return Whole


def _short_data(self: Any, data: bytes, header: Any, subscriptions: Any, ulog: Any) -> bool:
    """A data record too short to hold its message id is corruption (see ``_whole``): what
    pyulog's ``_MessageData.initialize`` says of a damaged record. Set on the one record (an
    instance attribute, by ``_Header``), so that every other record is decoded by pyulog's own
    method, without a call of fuzzoff's around it (10 % of reading a ULog, issue 31)."""
    del self.initialize
    self.timestamp = 0
    return True


class _TrackedULog(ULog):  # type: ignore[misc]
    """pyulog's ``ULog``, observed (see the module docstring)."""

    _MessageInfo = _whole(ULog._MessageInfo)
    _MessageParameterDefault = _whole(ULog._MessageParameterDefault)
    MessageLogging = _whole(ULog.MessageLogging)
    MessageLoggingTagged = _whole(ULog.MessageLoggingTagged)
    MessageDropout = _whole(ULog.MessageDropout)

    def __init__(
        self,
        path: str,
        topics: Sequence[str] | None,
        header_only: bool,
        plan: RowPlan | None = None,
    ) -> None:
        self._plan = plan
        self.framed: Framed | None = None
        """What the framing pass handed pyulog (``framing``), None: pyulog read the file."""
        self.framing_failed = False
        """pyulog's read of the framed records disagreed with the framing (``load`` reads
        the file again, whole)."""
        self.rows_read: dict[tuple[str, int], Any] = {}
        """(topic, instance) -> the rows decoded, where not every row was (the others hold
        zeros)."""
        self._headers: list[tuple[str, _Header]] = []
        self._section = "definitions"
        self._corruption: _Corruption | None = None
        self.missing_formats: list[str] = []
        self.missing_format_offset: int | None = None
        self.format_offsets: dict[str, int] = {}
        """Format name -> where its ``F`` record starts."""
        self.damaged_formats: dict[str, tuple[int, str]] = {}
        """Format name -> (where its record starts, what is wrong with it)."""
        self._MessageHeader = self._new_header
        self._MessageData = self._new_data
        self._MessageAddLogged = self._add_logged
        self.MessageFormat = self._format_record
        with open(path, "rb") as file:
            super().__init__(
                _DefinitionsHandle(file),
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
            header = self._headers[-1][1] if self._headers else _Header(16)
            last = getattr(self, "_last_timestamp", 0)
            self._corruption = _Corruption(
                self._section,
                header.start,
                header.end,
                not _implausible(header),
                header.partial,
                last,
            )

    def _new_header(self) -> _Header:
        handle = getattr(self, "_file_handle", None)
        start = handle.tell() if handle is not None else 16
        header = _Header(start)
        self._headers.append((self._section, header))
        return header

    def _new_data(self) -> Any:
        """pyulog's reusable data record, made right after the data section's header."""
        record = ULog._MessageData()
        if self._headers:
            self._headers[-1][1].data = record
        return record

    def _format_record(self, data: bytes, header: _Header) -> Any:
        """pyulog's ``MessageFormat``, with where it starts and what its text gets wrong."""
        fmt = ULog.MessageFormat(data, header)
        start = header.end - 3 - header.msg_size
        self.format_offsets.setdefault(fmt.name, start)
        damage = _format_damage(data)
        if damage is not None:
            self.damaged_formats.setdefault(fmt.name, (start, damage))
        return fmt

    def _add_logged(self, data: bytes, header: Any, formats: dict[str, Any]) -> Any:
        try:
            return ULog._MessageAddLogged(data, header, formats)
        except struct.error as exc:  # as ``_whole``
            raise ValueError(f"record too short ({exc})") from None
        except KeyError:
            name = ULog.parse_string(data[3:])
            # The name may be the damaged part: which topic lost its data cannot be known.
            if self.missing_format_offset is None and self._headers:
                self.missing_format_offset = self._headers[-1][1].start
            if name not in self.missing_formats:
                self.missing_formats.append(name)
            raise

    def _read_file_data(self, message_name_filter_list: Any, read_until: Any = None) -> None:
        self._section = "data"
        handle = getattr(self, "_file_handle", None)
        if isinstance(handle, _DefinitionsHandle):
            self._file_handle = handle.file
        if (
            self._plan is not None
            and message_name_filter_list is not None
            and read_until is None
            and not self.has_data_appended
            and not self.damaged_formats
            and self._corruption is None
        ):
            framed = self._frame(self._file_handle, message_name_filter_list)
            if framed is not None:
                self.framed = framed
                self._file_handle = io.BytesIO(framed.data)
                super()._read_file_data(message_name_filter_list)
                self._expand(framed)
                self._take_first(framed)
                return
        super()._read_file_data(message_name_filter_list, read_until)

    def _frame(self, file: BinaryIO, topics: Sequence[str]) -> Framed | None:
        """The framing pass over the data section, from where ``file`` is (``framing``), on
        the file mapped into memory (read in place: no copy of it)."""
        assert self._plan is not None
        start = file.tell()
        try:
            size = os.fstat(file.fileno()).st_size
            if not 0 < size - start <= LIMIT or size >= 1 << 31:
                return None
            mapped = mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ)
        except (OSError, ValueError, io.UnsupportedOperation):
            return None
        try:
            return frame(
                mapped, start, self._message_formats, self._start_timestamp, self._plan, topics
            )
        finally:
            with contextlib.suppress(BufferError):  # a view still held: closed when it goes
                mapped.close()

    def _expand(self, framed: Framed) -> None:
        """The thinned topic instances to their full length: every row's timestamp, the rows
        read in their places, zeros in the others (``rows_read`` says which are which)."""
        found = 0
        for data in self._data_list:
            key = (data.name, data.multi_id)
            if key not in framed.partial:
                continue
            found += 1
            stamps, rows = framed.partial[key]
            columns = data.data
            if not np.array_equal(columns.get("timestamp"), stamps[rows]):
                self.framing_failed = True
                return
            for name, column in columns.items():
                full = np.zeros(len(stamps), dtype=column.dtype)
                full[rows] = column
                columns[name] = full
            columns["timestamp"] = stamps
            self.rows_read[key] = rows
        if found != len(framed.partial) or self._last_timestamp != framed.last_timestamp:
            self.framing_failed = True

    def _take_first(self, framed: Framed) -> None:
        """The framing pass's whole decode of the status and declarations in place of the main
        pass's (which read only their rows that date a record), in pyulog's order."""
        taken = {(d.name, d.multi_id) for d in framed.first}
        kept = [d for d in self._data_list if (d.name, d.multi_id) not in taken]
        self._data_list[:] = sorted([*kept, *framed.first], key=lambda d: (d.name, d.multi_id))

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
    rows_read: dict[tuple[str, int], Any] = field(default_factory=dict)
    """(topic, instance) -> the rows pyulog decoded, where not all (``load``'s ``plan``)."""


def load(
    path: Path,
    topics: Sequence[str] | None,
    *,
    header_only: bool = False,
    seconds: Callable[[int], float] | None = None,
    plan: RowPlan | None = None,
) -> Loaded:
    """Read ``path`` with pyulog (only ``topics``; all when None). Raises ``SourceError`` when
    the file is not a readable ULog at all; damage after the header becomes ``problems``.

    With a ``plan`` (and ``topics``), pyulog decodes only the rows the plan reads where the
    framing pass can tell them (``framing``); ``Loaded.rows_read`` names the topic instances
    not read whole. Where that read says anything at all is wrong, the file is read again
    without the plan, so every problem is said as the plain read says it."""
    try:
        size = os.path.getsize(path)
    except OSError as exc:
        raise SourceError(path, f"cannot open: {exc.strerror or exc}") from None
    captured = io.StringIO()
    try:
        with contextlib.redirect_stdout(captured):
            ulog = _TrackedULog(str(path), topics, header_only, plan)
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
    if not header_only:
        loaded.problems.extend(_drop_damaged_formats(ulog, topics))
    loaded.problems.extend(_drop_unreadable_parameters(ulog))
    if ulog.framed is not None:
        if ulog.framing_failed or loaded.problems or loaded.library_output:
            return load(path, topics, header_only=header_only, seconds=seconds)
        loaded.rows_read = ulog.rows_read
    return loaded


_IDENTIFIER = r"[A-Za-z_][A-Za-z0-9_]*"
_NAME = re.compile(_IDENTIFIER)
_FIELD = re.compile(rf"({_IDENTIFIER})(?:\[([1-9][0-9]*)\])? ({_IDENTIFIER})")
_BASIC_TYPES = frozenset(ULog._UNPACK_TYPES)
MAX_FORMAT_LINES = 5
"""Damaged format records named one line each; the rest are counted."""


def capped(text: str, limit: int = 40) -> str:
    """A name from the file, cut: a damaged one can be any length (reports escape the rest)."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def quoted(text: str, limit: int = 40) -> str:
    return f"'{capped(text, limit)}'"


def _format_damage(data: bytes) -> str | None:
    """What a format record's text gets wrong, or None.

    The ULog grammar is ``name:type field;type[n] field;...`` with C identifiers (PX4 generates
    C structs from these), and every uORB message starts with ``uint64_t timestamp``. A flipped
    byte in a field name or type usually still parses, and pyulog then decodes the topic under
    the wrong name: its values read as absent, or its times as zero."""
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError:
        return "bytes that are not text"
    name, colon, body = text.partition(":")
    if not colon or not _NAME.fullmatch(name):
        return f"a topic name that is not an identifier: {quoted(name)}"
    items = body.split(";")
    if items and not items[-1]:
        items.pop()  # the ';' that ends the last field
    seen: set[str] = set()
    for item in items:
        match = _FIELD.fullmatch(item)
        if match is None:
            return f"a field that is not 'type name': {quoted(item)}"
        member = match.group(3)
        if member in seen:
            return f"the field {quoted(member)} twice"
        seen.add(member)
    if not any(item == "uint64_t timestamp" for item in items):
        return "no 'uint64_t timestamp' field"
    return None


def _drop_damaged_formats(ulog: _TrackedULog, topics: Sequence[str] | None) -> list[SourceProblem]:
    """Each damaged format record, one line, and the data of every topic it describes (itself
    or nested in it) taken out: decoded under a damaged definition, values would be wrong
    without a sign. A record that only topics fuzzoff does not read depend on costs nothing:
    it is said as a malformed part (``lost=False``)."""
    formats = ulog.message_formats
    damaged = dict(ulog.damaged_formats)
    for name, fmt in formats.items():
        for type_name, _, _member in fmt.fields:
            if type_name not in _BASIC_TYPES and type_name not in formats and name not in damaged:
                where = ulog.format_offsets.get(name, 16)
                damaged[name] = (where, f"a field of a type no format defines: {quoted(type_name)}")
    if not damaged:
        return []
    users = _users(formats, set(damaged))
    read = set(topics) if topics is not None else None
    kept = []
    lost: dict[str, set[str]] = {}
    for data in ulog.data_list:
        hit = [d for d, names in users.items() if data.name in names]
        if hit and (read is None or data.name in read):
            for d in hit:
                lost.setdefault(d, set()).add(data.name)
        else:
            kept.append(data)
    ulog.data_list[:] = kept
    problems = []
    for name, (start, why) in sorted(damaged.items(), key=lambda item: item[1][0]):
        gone = sorted(lost.get(name, ()))
        what = f"damaged format record of {quoted(name)} ({why})"
        if gone:
            what += f"; the messages of {', '.join(quoted(t) for t in gone)} were not read"
        else:
            what += "; no topic fuzzoff reads depends on it"
        problems.append(SourceProblem(what, f"byte {start}", lost=bool(gone)))
    if len(problems) > MAX_FORMAT_LINES:
        rest = problems[MAX_FORMAT_LINES:]
        problems = problems[:MAX_FORMAT_LINES]
        what = f"{len(rest)} more damaged format records"
        problems.append(SourceProblem(what, lost=any(p.lost for p in rest)))
    return problems


def _users(formats: dict[str, Any], damaged: set[str]) -> dict[str, set[str]]:
    """Damaged format -> the formats that are it or nest it, at any depth."""
    users: dict[str, set[str]] = {}
    for name in damaged:
        found = {name}
        grown = True
        while grown:
            grown = False
            for other, fmt in formats.items():
                if other not in found and any(t in found for t, _, _ in fmt.fields):
                    found.add(other)
                    grown = True
        users[name] = found
    return users


def _drop_unreadable_parameters(ulog: Any) -> list[SourceProblem]:
    """pyulog hands on the raw bytes of a parameter whose type it does not know (a damaged
    type name, since PX4 logs only int32 and float parameters): those are taken out, so that
    every parameter read on is a number, and said (the record's framing was intact, so
    pyulog itself reports nothing)."""
    names = [n for n, v in ulog.initial_parameters.items() if not _number(v)]
    for name in names:
        del ulog.initial_parameters[name]
    changed = ulog.changed_parameters
    names += [n for _, n, v in changed if not _number(v)]
    changed[:] = [entry for entry in changed if _number(entry[2])]
    if not names:
        return []
    what = f"damaged parameter records (a type no logger writes), skipped: {_some(names)}"
    return [SourceProblem(what)]


def _some(names: list[str]) -> str:
    """The first three names (each cut, see ``capped``), and how many more."""
    more = f" and {len(names) - 3} more" if len(names) > 3 else ""
    return ", ".join(capped(name) for name in names[:3]) + more


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


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
    ulog: _TrackedULog,
    size: int,
    header_only: bool,
    to_s: Callable[[int], float],
) -> list[SourceProblem]:
    """At most one problem: the first thing that went wrong (later damage follows from it)."""
    definitions = ulog.last_header("definitions")
    cut = definitions is not None and (definitions.partial or definitions.end > size)
    corruption = ulog.corruption
    # pyulog also flags a record that the end of the file cut short (or a header cut in two):
    # that is a truncation, unless the record's header is one no logger writes.
    cut_short = cut and corruption is not None and (corruption.plausible or corruption.partial)
    if corruption is not None and corruption.section == "definitions" and not cut_short:
        what = "broken definition section (formats, info or parameters unreadable)"
        return [SourceProblem(what, f"byte {corruption.start}")]
    if cut:
        return [SourceProblem("truncated in the definition section", f"byte {size}")]
    if ulog.missing_formats:
        what = (
            "broken definition section: no message format for topic "
            f"{_some(ulog.missing_formats)} (its data cannot be decoded)"
        )
        where = f"byte {ulog.missing_format_offset} (the topic's subscription record)"
        return [SourceProblem(what, where)]
    if corruption is not None:
        t = to_s(corruption.last_timestamp) if corruption.last_timestamp else None
        after = f", after the last good message at {t:.3f} s" if t is not None else ""
        what = "corrupt data: damaged records were skipped and reading resumed after them"
        return [SourceProblem(what, f"byte {corruption.end}{after}", time_s=t)]
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
