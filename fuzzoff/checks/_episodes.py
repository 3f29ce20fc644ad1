"""One finding per stretch of offending messages, not one per message.

A stream repeats the same mistake at 20-50 Hz; a finding per message would bury the report.
``Episodes`` keeps one open stretch per (code, stream, key): it opens at the first offending
message and grows while messages of that stream keep offending the same way with less than
``MERGE_GAP_S`` between them, so clean messages interleaved with bad ones (two senders, or a
program that alternates two kinds of setpoint) do not split it. A stretch is reported (at its
first message, with ``end`` = its last) when it is closed: by a longer pause in the offence, by
``clear`` (e.g. the vehicle left offboard) or at the end of the recording.
"""

from __future__ import annotations

from fuzzoff.checks.base import CheckContext
from fuzzoff.events import Where
from fuzzoff.findings import Severity
from fuzzoff.lean_dataclass import dataclass

MERGE_GAP_S = 1.0
"""Offending messages closer than this belong to one stretch."""


@dataclass(slots=True)
class Offence:
    """What one message did wrong, in the words of the finding."""

    message: str
    severity: Severity | None = None
    short: str = ""
    """The key fact for a terminal line (else the message's first statement)."""


@dataclass(slots=True)
class _Open:
    offence: Offence
    t: float
    where: Where
    last_t: float
    count: int = 1


class Episodes:
    """Open stretches of one check, by ``(code, stream, key)``."""

    def __init__(self, ctx: CheckContext) -> None:
        self.ctx = ctx
        self.open: dict[tuple[str, str, str], _Open] = {}

    def update(
        self, code: str, stream: str, t: float, where: Where, offences: dict[str, Offence]
    ) -> None:
        """This message of ``stream`` commits ``offences`` (key -> offence) under ``code``."""
        if not offences and not self.open:
            return  # the common case: a clean message and nothing open
        for key in [k for k in self.open if k[0] == code and k[1] == stream]:
            if t - self.open[key].last_t > MERGE_GAP_S:
                self._close(key)
        for name, offence in offences.items():
            key = (code, stream, name)
            current = self.open.get(key)
            if current is None:
                self.open[key] = _Open(offence, t, where, t)
            else:
                current.last_t = t
                current.count += 1

    def extend(self, key: tuple[str, str, str], last_t: float, count: int) -> None:
        """``update`` for ``count`` more messages committing the open stretch ``key``, the
        newest at ``last_t``, with nothing to close in between: only its end and count move."""
        stretch = self.open[key]
        stretch.last_t = last_t
        stretch.count += count

    def start(
        self,
        code: str,
        stream: str,
        key: str,
        offence: Offence,
        span: tuple[float, Where, float, int],
    ) -> None:
        """Open a stretch judged late: ``span`` = (first t, where, last t, message count)."""
        t, where, last_t, count = span
        self.open[(code, stream, key)] = _Open(offence, t, where, last_t, count)

    def clear(self, code: str, stream: str | None = None) -> None:
        """Close every stretch of ``code`` (of one ``stream`` if given)."""
        for key in [k for k in self.open if k[0] == code and stream in (None, k[1])]:
            self._close(key)

    def finish(self) -> None:
        for key in list(self.open):
            self._close(key)

    def _close(self, key: tuple[str, str, str]) -> None:
        stretch = self.open.pop(key)
        message = stretch.offence.message
        if stretch.count > 1:
            message += f" ({stretch.count} messages, until t={stretch.last_t:.2f} s)"
        self.ctx.report(
            key[0],
            message,
            stretch.t,
            stretch.where,
            severity=stretch.offence.severity,
            end=stretch.last_t if stretch.count > 1 else None,
            short=stretch.offence.short,
        )
