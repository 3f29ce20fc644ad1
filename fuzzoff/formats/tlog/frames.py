"""Split a .tlog into records and hand the packets that matter to pymavlink (formats.md 7).

A tlog is ``[8-byte big-endian µs timestamp][one MAVLink packet]`` repeated, with no header or
index. pymavlink decodes the packets; this module only finds where each record starts and ends
(the packet length is in its header) and decides which packets to decode.

Why not ``mavutil.mavlink_connection`` (which gives a ``mavmmaplog``)? Measured against the
targets of issue 3 part 10 (see bench/bench_tlog.py):

* its type filter needs its index, built by a pure-Python pre-scan that keeps one list entry
  per message: memory grows with the file (about 40 MB per million messages), and every page of
  the mmapped file it touches counts in the process's RSS, so peak RSS grows with the file too;
* the pre-scan silently steps over bytes it cannot frame and over message ids the dialect does
  not know, so a corrupt region is never reported, and with a type filter the skipped messages
  are never CRC-checked at all;
* without a filter it decodes everything (about 90 000 messages/s), which is what we must beat
  on logs where offboard messages are a small share.

So the file is read sequentially in fixed-size chunks (flat memory, no mmap), each record is
framed here, the wanted message types go to pymavlink's ``MAVLink.decode`` (header, CRC with
CRC_EXTRA, payload unpacking) and every other known packet only has its CRC checked with
pymavlink's ``x25crc``, so corruption anywhere is still found. After a bad record the reader
resynchronises on the next record whose timestamp is plausible and whose CRC is good, and
reports the skipped bytes as one corrupt region.

The dialect is pymavlink's ``development``: PX4 is built with MAVLink's development dialect
(``common`` plus the messages still being standardised), and every PX4 release here sends some
of them (CURRENT_MODE 436, GNSS_INTEGRITY 441) on every link. Not ``all``: it adds ArduPilot's
and other vendors' dialects, which give the dialect id range (150-229 and beyond) meanings PX4
never uses, so a vendor packet there would be CRC-checked against a foreign CRC_EXTRA and
called corrupt, or decoded with a foreign meaning. A packet whose id the dialect does not know
(PX4 also sends ids newer than pymavlink's copy of the dialect: 8, 380, 410, 411 in 1.14-1.18)
is ordinary traffic: it has no CRC_EXTRA to check it with, so it is accepted when its framing
holds (its length leads to the next record's start byte, or to the end of the file) and counted.
"""

from __future__ import annotations

import os
import re
import struct
from collections import Counter
from collections.abc import Callable, Iterator, Mapping
from dataclasses import field
from typing import Any, BinaryIO

from fuzzoff.lean_dataclass import dataclass

os.environ.setdefault("MAVLINK20", "1")  # formats.md 7.2: before any pymavlink import

from pymavlink.dialects.v20 import development as mavlink

CHUNK = 1 << 20
"""Bytes read at a time; memory stays at a few chunks whatever the file size."""

MAX_RECORD = 8 + 10 + 255 + 2 + 13
"""Largest record: timestamp, MAVLink 2 header, payload, CRC, signature."""

LOOKAHEAD = MAX_RECORD + 9
"""Bytes kept in the buffer past a record's start: the record and the next one's start byte."""

BACKWARD_US = 100_000
"""A record may be this much older than the one before it without a second look."""

FORWARD_US = 250_000
"""Or this much newer. A larger step is checked against the next record (``_step_real``)."""

FIRST_STEP_US = 60_000_000
"""The first record is doubted when the second is more than this far from it; a step this
large is doubted when there is no next record to confirm it."""

RESYNC_WINDOW_US = (120_000_000, 86_400_000_000)
"""After bad bytes, a candidate record may be this much older / newer than the last good one."""

RESYNC_LIMIT = 16 << 20
"""Bytes searched for the next good record before giving up: a longer stretch without one is
not a damaged tlog but something else (a disk image, noise), and searching on would take minutes
on a large file without a result."""

MAX_UNKNOWN_IDS = 256
"""Distinct unknown message ids tracked one by one; beyond that they are only counted."""

_MAGIC = re.compile(b"[\xfd\xfe]")
_TS = struct.Struct(">Q")
_CRC = struct.Struct("<H")
_CRC_EXTRA: dict[int, int] = {mid: cls.crc_extra for mid, cls in mavlink.mavlink_map.items()}
_EXTRA_BYTE: tuple[bytes, ...] = tuple(bytes((i,)) for i in range(256))
_FAST_CRC: Callable[[bytes, int], int] | None = getattr(mavlink, "mcrf4xx", None)
_NAMES: dict[int, str] = {mid: cls.msgname for mid, cls in mavlink.mavlink_map.items()}


def message_name(msgid: int) -> str:
    return _NAMES.get(msgid, f"UNKNOWN_{msgid}")


@dataclass(slots=True)
class Region:
    """Bytes skipped as unreadable: [start, end) in the file, after the record at ``t_us``."""

    start: int
    end: int
    why: str
    ts_us: int | None


@dataclass(slots=True)
class FrameStats:
    packets: int = 0
    by_id: Counter[int] = field(default_factory=Counter)
    unknown: Counter[int] = field(default_factory=Counter)
    """Packets of ids the dialect does not define, well framed (so not corrupt), not decoded."""
    unknown_first: dict[int, tuple[int, int]] = field(default_factory=dict)
    """Unknown id -> (offset, timestamp) of its first packet."""
    unknown_other: int = 0
    regions: list[Region] = field(default_factory=list)
    truncated_at: int | None = None
    """Offset of an incomplete last record, if the file ends inside one."""
    stopped_at: int | None = None
    """Where reading gave up: ``RESYNC_LIMIT`` bytes without a good record."""
    first_ts: int | None = None
    last_ts: int | None = None
    size: int = 0


class Framer:
    """Iterate over the records of one tlog; decode only ``wanted`` message ids.

    ``verify`` CRC-checks the packets that are not decoded too (the lint pass); the probe
    leaves it off to stay cheap, so its counts may include a packet that later proves corrupt.
    """

    def __init__(
        self,
        fh: BinaryIO,
        size: int,
        wanted: frozenset[int],
        verify: bool,
        thinned: Mapping[int, int] | None = None,
    ) -> None:
        self.fh = fh
        self.wanted = wanted
        self.verify = verify
        self.thinned: Mapping[int, int] = thinned or {}
        """Wanted ids decoded at most once per period (µs) per sender system: the first packet
        of each period of the log's clock; the others are framed and CRC-checked only."""
        self._due_at: dict[tuple[int, int], int] = {}
        self.stats = FrameStats(size=size)
        self.mav = mavlink.MAVLink(None)
        self.mav.robust_parsing = True
        self.buf = b""
        self.base = 0
        self.eof = False
        self.consumed = 0
        self.on_chunk: Callable[[], None] | None = None
        """Called after each chunk read, so a long stretch with no record still shows progress."""
        self.on_thinned: Callable[[int, Any], None] | None = None
        """Called with (timestamp µs, decoded message) for each valid packet ``thinned`` left
        out, for a caller that plots it beside the records (None: not decoded at all)."""

    # -- buffer ---------------------------------------------------------------------------

    def _fill(self, pos: int) -> int:
        """Drop bytes before ``pos`` and read one more chunk; returns the new ``pos``."""
        chunk = self.fh.read(CHUNK)
        if not chunk:
            self.eof = True
        self.base += pos
        self.buf = self.buf[pos:] + chunk
        self.consumed = self.base
        if self.on_chunk is not None:
            self.on_chunk()
        return 0

    # -- checks ---------------------------------------------------------------------------

    def _record_end(self, buf: bytes, pos: int) -> int | None:
        """End of the record at ``pos`` from its header, or None if its start byte is wrong."""
        magic = buf[pos + 8]
        if magic == 0xFD:
            return pos + 20 + buf[pos + 9] + (13 if buf[pos + 10] & 1 else 0)
        if magic == 0xFE:
            return pos + 16 + buf[pos + 9]
        return None

    @staticmethod
    def _msgid(buf: bytes, pos: int) -> int:
        if buf[pos + 8] == 0xFD:
            return buf[pos + 15] | (buf[pos + 16] << 8) | (buf[pos + 17] << 16)
        return buf[pos + 13]

    @staticmethod
    def _crc_ok(buf: bytes, pos: int, end: int, msgid: int) -> bool:
        """pymavlink's CRC (x25 with the message's CRC_EXTRA); False for unknown ids."""
        extra = _CRC_EXTRA.get(msgid)
        if extra is None:
            return False
        crc_at = end - (13 if buf[pos + 8] == 0xFD and buf[pos + 10] & 1 else 0) - 2
        expected: int = _CRC.unpack_from(buf, crc_at)[0]
        if _FAST_CRC is not None:  # the routine pymavlink's x25crc calls, without its wrapper
            return bool(
                _FAST_CRC(_EXTRA_BYTE[extra], _FAST_CRC(buf[pos + 9 : crc_at], 0xFFFF)) == expected
            )
        crc = mavlink.x25crc(buf[pos + 9 : crc_at])
        crc.accumulate(_EXTRA_BYTE[extra])
        return bool(crc.crc == expected)

    def _due(self, buf: bytes, pos: int, msgid: int, ts: int) -> bool:
        """Is this packet of a thinned id the first of its period for its sender system?"""
        sysid = buf[pos + 13] if buf[pos + 8] == 0xFD else buf[pos + 11]
        period = self.thinned[msgid]
        key = (msgid, sysid)
        if ts < self._due_at.get(key, -1):
            return False
        self._due_at[key] = (ts // period + 1) * period
        return True

    def _aside(self, buf: bytes, pos: int, end: int, ts: int) -> None:
        """Decode a thinned packet (its CRC already checked) for ``on_thinned``."""
        assert self.on_thinned is not None
        try:
            msg = self.mav.decode(bytearray(buf[pos + 8 : end]))
        except (mavlink.MAVError, struct.error, ValueError, TypeError, IndexError):
            return
        self.on_thinned(ts, msg)

    def _plausible(self, ts: int) -> bool:
        last = self.stats.last_ts
        back, forward = RESYNC_WINDOW_US
        return last is None or last - back <= ts <= last + forward

    # -- main loop ------------------------------------------------------------------------

    def records(self) -> Iterator[tuple[int, int, int, Any]]:
        """(offset, timestamp µs, msgid, decoded message) for every wanted, valid packet."""
        stats = self.stats
        by_id = stats.by_id
        wanted = self.wanted
        verify = self.verify
        decode = self.mav.decode
        crc_ok = self._crc_ok
        unpack_ts = _TS.unpack_from
        buf = self.buf
        pos = 0
        n = 0
        first = True
        while True:
            if pos + 18 > n or (pos + LOOKAHEAD > n and not self.eof):
                if not self.eof:
                    pos = self._fill(pos)
                    buf = self.buf
                    n = len(buf)
                    continue
                if pos >= n:
                    break
            if pos + 11 > n:
                self._tail(pos)
                break
            # _record_end and _msgid inlined: this runs once per packet
            magic = buf[pos + 8]
            if magic == 0xFD:
                end = pos + 20 + buf[pos + 9] + (13 if buf[pos + 10] & 1 else 0)
            elif magic == 0xFE:
                end = pos + 16 + buf[pos + 9]
            else:
                pos, buf, n = self._resync(pos, "no MAVLink start byte")
                continue
            if end > n:
                self._tail(pos)
                break
            ts = unpack_ts(buf, pos)[0]
            if magic == 0xFD:
                msgid = buf[pos + 15] | (buf[pos + 16] << 8) | (buf[pos + 17] << 16)
            else:
                msgid = buf[pos + 13]
            last = stats.last_ts
            if (
                last is not None
                and not last - BACKWARD_US <= ts <= last + FORWARD_US
                and not self._step_real(buf, end, ts, last, n)
            ) or (last is None and not self._first_ts_ok(buf, end, ts, n)):
                pos, buf, n = self._resync(pos, "implausible timestamp")
                continue
            msg: Any = None
            if msgid in wanted and (msgid not in self.thinned or self._due(buf, pos, msgid, ts)):
                try:
                    msg = decode(bytearray(buf[pos + 8 : end]))
                except (mavlink.MAVError, struct.error, ValueError, TypeError, IndexError):
                    pos, buf, n = self._resync(pos, "bad CRC or length")
                    continue
            elif verify or first:
                if msgid not in _CRC_EXTRA:
                    if not self._framed(buf, end, ts, n):
                        why = "no MAVLink packet" if first else "bad length"
                        pos, buf, n = self._resync(pos, why)
                        continue
                    self._unknown(msgid, pos, ts)
                elif not crc_ok(buf, pos, end, msgid):
                    pos, buf, n = self._resync(pos, "bad CRC")
                    continue
                if msgid in wanted and self.on_thinned is not None:
                    self._aside(buf, pos, end, ts)
            elif msgid not in _CRC_EXTRA:
                self._unknown(msgid, pos, ts)
            first = False
            if stats.first_ts is None:
                stats.first_ts = ts
            stats.last_ts = ts
            by_id[msgid] += 1
            stats.packets += 1
            if msg is not None:
                yield self.base + pos, ts, msgid, msg
            pos = end
            self.consumed = self.base + pos
        self.consumed = stats.size

    def _framed(self, buf: bytes, end: int, ts: int, n: int) -> bool:
        """Does the record ending at ``end`` (one with no CRC to check) end where the next
        begins: a MAVLink start byte 8 bytes on, under a timestamp in line with this one, or
        the end of the file? A corrupt length or start byte seldom passes both."""
        if end + 9 > n:
            return self.eof and end == n
        if buf[end + 8] not in (0xFD, 0xFE):
            return False
        back, forward = RESYNC_WINDOW_US
        next_ts: int = _TS.unpack_from(buf, end)[0]
        return ts - back <= next_ts <= ts + forward

    def _unknown(self, msgid: int, pos: int, ts: int) -> None:
        stats = self.stats
        if msgid in stats.unknown or len(stats.unknown) < MAX_UNKNOWN_IDS:
            stats.unknown[msgid] += 1
            stats.unknown_first.setdefault(msgid, (self.base + pos, ts))
        else:
            stats.unknown_other += 1

    def _tail(self, pos: int) -> None:
        """The file ends inside a record at ``pos``."""
        if pos + 9 <= len(self.buf) and self.buf[pos + 8] not in (0xFD, 0xFE):
            size = len(self.buf) - pos
            self.stats.regions.append(
                Region(self.base + pos, self.base + pos + size, "garbage", self.stats.last_ts)
            )
        else:
            self.stats.truncated_at = self.base + pos

    def _next_ts(self, buf: bytes, end: int, n: int) -> int | None:
        """Timestamp of the record at ``end`` if one visibly starts there."""
        if end + 11 > n or self._record_end(buf, end) is None:
            return None
        ts: int = _TS.unpack_from(buf, end)[0]
        return ts

    def _step_real(self, buf: bytes, end: int, ts: int, last: int, n: int) -> bool:
        """A time step is real (a pause in the log, a clock step) if the next record is nearer
        to the new time than to the old one; a corrupt timestamp is a spike the next record
        does not follow. With no next record to judge by, only a step under a minute stands."""
        ts2 = self._next_ts(buf, end, n)
        if ts2 is None:
            return abs(ts - last) <= FIRST_STEP_US
        return abs(ts2 - ts) < abs(ts2 - last)

    def _first_ts_ok(self, buf: bytes, end: int, ts: int, n: int) -> bool:
        """The first record has no predecessor: doubt it when the second is far away."""
        ts2 = self._next_ts(buf, end, n)
        return ts2 is None or abs(ts2 - ts) <= FIRST_STEP_US

    def _resync(self, bad: int, why: str) -> tuple[int, bytes, int]:
        """Find the next good record after ``bad``; record the skipped bytes as a region.

        A candidate is a start byte 8 bytes into a record whose timestamp is plausible, whose
        message id is known and whose CRC is good (unknown ids cannot be checked).
        """
        start_abs = self.base + bad
        qmin = bad + 9  # smallest index of a candidate's start byte
        while True:
            buf = self.buf
            n = len(buf)
            m = _MAGIC.search(buf, qmin)
            qmin = n
            while m is not None:
                q = m.start()
                cand = q - 8
                if cand + 11 > n or (cand + MAX_RECORD > n and not self.eof):
                    qmin = q  # judge this one after the next read
                    break
                end = self._record_end(buf, cand)
                if end is not None and end <= n:
                    ts = _TS.unpack_from(buf, cand)[0]
                    msgid = self._msgid(buf, cand)
                    if self._plausible(ts) and self._crc_ok(buf, cand, end, msgid):
                        self.stats.regions.append(
                            Region(start_abs, self.base + cand, why, self.stats.last_ts)
                        )
                        return cand, buf, n
                m = _MAGIC.search(buf, q + 1)
            if self.eof:
                self.stats.regions.append(Region(start_abs, self.base + n, why, self.stats.last_ts))
                return n, buf, n
            if self.base + qmin - start_abs > RESYNC_LIMIT:
                stop = self.base + qmin
                self.stats.regions.append(Region(start_abs, stop, why, self.stats.last_ts))
                self.stats.stopped_at = stop
                self.eof, self.buf = True, b""
                return 0, b"", 0
            keep = max(0, qmin - 8)
            self._fill(keep)
            qmin -= keep
