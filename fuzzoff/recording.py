"""What every reader provides: a probe of the recording, then its events in time order.

A reader never judges. It raises ``SourceError`` when the file cannot be read at all (empty,
foreign, no header) and records a ``SourceProblem`` when part of it cannot be read (truncated,
corrupt), after yielding every event it could read before that point. Damage that cost no data
(trailing garbage, a broken index read around) is a ``SourceProblem`` with ``lost=False``.
"""

from __future__ import annotations

import abc
import math
import os
import re
from collections.abc import Callable, Iterator
from dataclasses import field
from pathlib import Path
from types import TracebackType

from fuzzoff.events import Event, VehiclePosition
from fuzzoff.findings import RecordingStats
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.releases import Release


def path_text(path: Path | str) -> str:
    """A path as report text: bytes of its name that are not UTF-8 (which Python keeps as lone
    surrogates, and no UTF-8 report can hold) shown as ``\\xNN``."""
    return os.fsencode(path).decode("utf-8", "backslashreplace")


POSITION_PERIOD_S = 1.0
"""A plain lint reads the vehicle's position at most this often per vehicle and topic (the
first message of each period; the others are not decoded): OFB404 compares a setpoint with
the vehicle's height on the ground, which moves slowly, and every event between two runs of
setpoints costs the checks a run (``StreamBatch``). The HTML report plots the others too, but
they reach it beside the judged events (``PlotSamples``), never through the gate or the checks."""

PLOT_SAMPLE_S = 0.05
"""Shortest time between two kept samples of a plotted series (20 Hz is plenty for a plot)."""

WHAT_LIMIT = 300
WHERE_LIMIT = 120
"""A problem's line stays short whatever the file names in it (a garbage topic name)."""


def _cut(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


_FIRST_BYTE = re.compile(r"bytes? (\d+)\b")


def first_byte(where: str | None) -> int | None:
    """The byte of the file a problem's ``where`` starts at, when it names one: readers write
    ``byte N``, ``bytes A-B``, ``byte N of SIZE``, ``byte N (why)``. None for anything else
    (a topic, a message count, a byte of another file inside a ROS 2 bag's folder)."""
    if where is None:
        return None
    found = _FIRST_BYTE.match(where)
    return int(found.group(1)) if found else None


class SourceError(Exception):
    """The recording cannot be read at all. ``str()`` is the one line the user sees."""

    def __init__(self, path: Path | str, what: str, where: str | None = None) -> None:
        self.path = path_text(path)
        self.what = what
        self.where = where
        super().__init__(self.line())

    def line(self) -> str:
        at = f" at {_cut(self.where, WHERE_LIMIT)}" if self.where else ""
        return f"{self.path}: {_cut(self.what, WHAT_LIMIT)}{at}"


@dataclass(frozen=True, slots=True)
class SourceProblem:
    """Part of a recording that could not be read; everything before it was."""

    what: str
    where: str | None = None
    time_s: float | None = None
    lost: bool = True
    """False for a malformed part the reader read around without losing a message (OFB004,
    the file stays complete); True for data not read (OFB001)."""

    def line(self, path: str) -> str:
        at = f" at {_cut(self.where, WHERE_LIMIT)}" if self.where else ""
        return f"{path}: {_cut(self.what, WHAT_LIMIT)}{at}"


@dataclass(slots=True)
class RecordingInfo:
    """What a reader learns before (or without) decoding messages.

    ``kinds`` is the set of event kinds the recording can produce (``Event.kind`` values), so a
    rule can say it is not checkable before seeing the stream. ``sampled_intervals`` is set for
    recordings that subsample topics (ULog): event kind -> the logger's interval in seconds.
    """

    path: str
    format: str
    kinds: set[str] = field(default_factory=set)
    px4_version: str | None = None
    px4_branch: str | None = None
    """The source branch the build names (ULog ``ver_sw_branch``): tells main from the release
    branch whose version main reports."""
    px4_candidates: list[str] = field(default_factory=list)
    """Where the recording does not name its release but narrows it (a ROS 2 recording's
    message definitions and topic names): the profiles it fits, oldest first."""
    px4_msgs_fits: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """A ROS 2 recording's PX4 topics -> the px4_msgs releases (oldest first) that each one's
    name and embedded definition fit (OFB006 compares the companion's and PX4's)."""
    px4_msgs_conflicts: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = field(
        default_factory=dict
    )
    """Its PX4 topics whose name and embedded definition fit no release together -> (releases
    the name fits, releases the definition fits) (OFB006)."""
    vehicle_type: str | None = None
    vehicles: list[str] = field(default_factory=list)
    message_count: int | None = None
    sampled_intervals: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    vehicle_assumed: str | None = None
    """What part of ``vehicle_type`` the recording does not say, and what was assumed for it
    (a rover whose kind is not recorded): reported as OFB003 unless ``--vehicle`` is given."""
    stream_recorded: bool = True
    """Does the recording hold the stream sent to the vehicle, or at least the link that would
    carry it? False only where the reader can tell it does not: a ground station's tlog, with
    no setpoint and no command from a companion (PX4 does not forward messages addressed to
    itself), or a ULog without ``offboard_control_mode`` (a logger profile that leaves it out,
    a log cut to other topics), where the absence of a stream says nothing about the sender."""
    stream_missing: str = ""
    """With ``stream_recorded`` false: what the recording is, and why it cannot hold the
    stream (the OFB002 finding says it)."""

    @property
    def sampled(self) -> bool:
        return bool(self.sampled_intervals)


class PlotSamples:
    """What only the HTML report's plots show: the vehicle's positions, per vehicle (t, x, y,
    z), at most one per ``PLOT_SAMPLE_S`` of the samples given in time order."""

    def __init__(self) -> None:
        self.positions: dict[str, list[tuple[float, float, float, float]]] = {}

    def position(self, event: VehiclePosition) -> None:
        add_sample(self.positions.setdefault(event.vehicle, []), event.t, _xyz(event))


def _xyz(event: VehiclePosition) -> tuple[float, float, float]:
    return (event.x, event.y, event.z)


def add_sample(
    series: list[tuple[float, float, float, float]], t: float, xyz: tuple[float, float, float]
) -> None:
    """Append (t, x, y, z) unless it is all NaN or within ``PLOT_SAMPLE_S`` of the last one."""
    if any(math.isfinite(v) for v in xyz) and (not series or t - series[-1][0] >= PLOT_SAMPLE_S):
        series.append((t, *xyz))


@dataclass(slots=True)
class Aside:
    """What a reader read but left out of the events, kept beside them (issue 26): the gate
    and the checks never see it, so neither the outputs asked for nor a reader's thinning
    changes what is judged.

    ``end_t`` is the time of the last message the reader read, event or not: the recording
    ends there, not at its last event (checks judge up to the end: a keep-alive gap, a run
    still open). ``plot`` is set by a caller that plots: readers then hand it the positions
    they thin out of the events (``POSITION_PERIOD_S``)."""

    plot: PlotSamples | None = None
    end_t: float | None = None

    def read(self, t: float) -> None:
        """A message at ``t`` was read and left out of the events (a thinned position)."""
        if self.end_t is None or t > self.end_t:
            self.end_t = t


class Source(abc.ABC):
    """One recording of one format. Use as a context manager."""

    format: str = "?"

    def __init__(self, path: Path) -> None:
        self.path = path
        self.problems: list[SourceProblem] = []
        self.stats = RecordingStats()
        self.on_progress: Callable[[], None] | None = None
        """Set by the caller that shows progress: a reader that reads a long stretch without
        an event (a tlog's garbage) calls it now and then."""
        self.px4_hint: Release | None = None
        """The user's ``--px4`` release record, set before ``open()``: readers that must choose
        message definitions the recording does not carry (Humble-era ROS 2 bags) start from
        its ``msg_folder``."""
        self.aside = Aside()
        """What the reader read beside the events: the last message's time, and the plotted
        positions it thinned out (``aside.plot``, set before ``events()``)."""
        self.start_time_s: float | None = None
        """The recording's first time on the wall clock (UNIX seconds), where it has one; set
        by ``events()``. ``t`` of every event counts from it."""

    def __enter__(self) -> Source:
        self.open()
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def open(self) -> None:  # noqa: B027 - optional hook
        """Open the file; raise ``SourceError`` if it cannot be read at all."""

    def close(self) -> None:  # noqa: B027 - optional hook
        """Release the file."""

    @abc.abstractmethod
    def probe(self) -> RecordingInfo:
        """What the recording holds, read cheaply (header, index, summary)."""

    @abc.abstractmethod
    def events(self) -> Iterator[Event]:
        """The normalised events in recording-time order; streaming where the library can."""

    def set_start(self, unix_s: float | None) -> None:
        """Keep ``unix_s`` as the start time if it reads as a wall clock (after 2001): a
        simulation clock or a boot clock starts near 0 and says nothing about the date."""
        if unix_s is not None and 1e9 < unix_s < 1e10:
            self.start_time_s = unix_s

    def progress(self) -> float | None:
        """Fraction of the file consumed so far, where the reader can tell."""
        return None
