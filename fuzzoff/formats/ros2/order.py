"""Time order for a stream read in file order (MCAP without ``log_time_order``, formats.md 4.2).

Recorders write messages in arrival order, chunk by chunk, so a file is ordered except inside a
chunk and where consecutive chunks overlap. ``ChunkOrder`` holds the decoded events of the chunks
not yet known to be complete in time: events are released once a chunk starting after them
arrives. Memory is bounded by the PX4 events of about two chunks, never the file. An event older
than one already released (disorder across more than a chunk) is released late and counted in
``late``; readers report the count.
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Iterator

from fuzzoff.events import Event
from fuzzoff.lean_dataclass import dataclass

MAX_PENDING = 8192
"""Events held at most when the file has no chunks to mark boundaries."""


class ChunkOrder:
    """Reorders events between chunk boundaries (see module docstring)."""

    @dataclass(frozen=True, slots=True)
    class Boundary:
        """A chunk starts; none of its messages is older than ``start_ns``."""

        start_ns: int

    def __init__(self) -> None:
        self._pending: list[tuple[int, int, Event]] = []
        self._sorted = True
        self._seq = 0
        self._last = -1
        self.late = 0

    def add(self, time_ns: int, event: Event) -> Iterator[Event]:
        """Queue an event (outside chunks it is released at once when in order)."""
        pending = self._pending
        if pending and time_ns < pending[-1][0]:
            self._sorted = False
        self._seq += 1
        pending.append((time_ns, self._seq, event))
        if len(pending) > MAX_PENDING:  # no chunk boundaries (unchunked file): a bounded window
            return self._release(None, MAX_PENDING // 2)
        return iter(())

    def boundary(self, start_ns: int) -> Iterator[Event]:
        """A new chunk begins at ``start_ns``: release what is older."""
        return self._release(start_ns)

    def flush(self) -> Iterator[Event]:
        return self._release(None)

    def _release(self, until: int | None, count: int | None = None) -> Iterator[Event]:
        pending = self._pending
        if not pending:
            return
        if not self._sorted:
            pending.sort(key=_key)
            self._sorted = True
        if count is not None:
            cut = count
        elif until is None:
            cut = len(pending)
        else:
            cut = bisect_right(pending, until, key=_time)
        last = self._last
        for time_ns, _, event in pending[:cut]:
            if time_ns < last:
                self.late += 1
            else:
                last = time_ns
            yield event
        self._last = last
        del pending[:cut]


def _time(item: tuple[int, int, Event]) -> int:
    return item[0]


def _key(item: tuple[int, int, Event]) -> tuple[int, int]:
    return (item[0], item[1])
