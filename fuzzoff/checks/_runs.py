"""Helpers for the checks' ``on_batch``.

``commit_alike`` commits to ``Episodes`` a run whose verdicts are known without each message;
``first_of_each`` picks the message to judge for each verdict key; ``sent_only`` keeps the
messages recorded on their way to the vehicle.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from itertools import repeat
from operator import attrgetter, le, sub
from typing import TypeVar

from fuzzoff.checks._episodes import MERGE_GAP_S, Episodes, Offence
from fuzzoff.events import Event

Verdicts = list[tuple[str, dict[str, Offence]]]
"""What one message commits, as ``Episodes.update`` takes it: (code, offences), in order."""

_T = attrgetter("t")
_ORIGIN = attrgetter("origin")
_SENT = {"sent"}

K = TypeVar("K", bound=Hashable)


def first_of_each(key: Callable[[Event], K], events: list[Event]) -> dict[K, Event]:
    """The first message of each ``key``, in order of first appearance (a run usually has
    one key: then without a pass that builds the dict message by message)."""
    keys = set(map(key, events))
    if len(keys) == 1:
        return {keys.pop(): events[0]}
    first: dict[K, Event] = {}
    for event in events:
        first.setdefault(key(event), event)
    return first


def sent_only(events: list[Event]) -> list[Event]:
    """The messages recorded on their way to the vehicle (origin ``sent``): ``events`` itself
    when all are. The MAVLink checks judge only these."""
    if not events or set(map(_ORIGIN, events)) == _SENT:
        return events
    return [e for e in events if e.origin == "sent"]


def commit_alike(
    episodes: Episodes, stream: str, events: list[Event], verdicts: list[Verdicts]
) -> bool:
    """``Episodes.update`` for a run of messages of one stream whose verdicts are known without
    each message: ``verdicts`` holds the distinct verdicts of the run. Done (True) when nothing
    is offended and nothing is open (``update`` then returns at once for every message), or when
    every message commits the same verdicts and only extends what the first one opens
    (``extend_alike``); False (nothing done): replay the run."""
    if not episodes.open and not any(offences for v in verdicts for _, offences in v):
        return True
    if len(verdicts) != 1:
        return False
    return extend_alike(episodes, stream, events, verdicts[0])


def extend_alike(episodes: Episodes, stream: str, events: list[Event], verdicts: Verdicts) -> bool:
    """Every message commits ``verdicts``: the first is committed as ``on_event`` does; the
    others only extend the stretches it opened, provided no gap between them exceeds
    ``MERGE_GAP_S`` and no other stretch of these codes and this stream is still open after
    the first (a later message could close it). False (nothing done) when that does not hold."""
    times = list(map(_T, events))
    if not all(map(le, map(sub, times[1:], times[:-1]), repeat(MERGE_GAP_S))):
        return False
    names: dict[str, set[str]] = {}
    for code, offences in verdicts:
        names.setdefault(code, set()).update(offences)
    for (code, where, name), stretch in episodes.open.items():
        other = where == stream and name not in names.get(code, (name,))
        if other and not times[0] - stretch.last_t > MERGE_GAP_S:  # update closes it, or not
            return False
    first = events[0]
    for code, offences in verdicts:
        episodes.update(code, stream, first.t, first.where, offences)
    more = len(events) - 1
    if more:
        for code, offences in verdicts:
            for name in offences:
                episodes.extend((code, stream, name), times[-1], more)
    return True
