"""Findings, severities, and the per-file report the engine returns."""

from __future__ import annotations

import re
from dataclasses import field
from enum import IntEnum
from typing import TYPE_CHECKING, Any, TypedDict

from fuzzoff.events import Where
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import Profile

if TYPE_CHECKING:
    from fuzzoff.bridge.compare import Delivery
    from fuzzoff.timeline import Timeline


class Severity(IntEnum):
    """Ordered so that ``severity >= fail_level`` reads naturally."""

    INFO = 0
    WARNING = 1
    ERROR = 2

    @property
    def label(self) -> str:
        return self.name.lower()

    @classmethod
    def parse(cls, text: str) -> Severity:
        try:
            return cls[text.strip().upper()]
        except KeyError:
            raise ValueError(f"unknown severity {text!r}: one of error, warning, info") from None


SHORT_LIMIT = 90
"""Longest summary a terminal line shows (characters): with the time, code, severity and
location it keeps a finding on one line of a 120-column terminal."""


def _top_level(text: str, separators: tuple[str, ...]) -> int:
    """Where the first separator stands outside brackets, or -1."""
    depth = 0
    for i, ch in enumerate(text):
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth = max(0, depth - 1)
        elif depth == 0 and any(text.startswith(sep, i) for sep in separators):
            return i
    return -1


def _without_brackets(text: str) -> str:
    out: list[str] = []
    depth = 0
    for ch in text:
        if ch == "(":
            depth += 1
        elif ch == ")" and depth:
            depth -= 1
        elif depth == 0:
            out.append(ch)
    return re.sub(r"\s+([,;:.])", r"\1", re.sub(r"\s{2,}", " ", "".join(out))).strip()


def shorten(message: str, limit: int = SHORT_LIMIT) -> str:
    """A message's first statement, for a terminal line: up to its first ``; `` or ``: ``
    outside brackets (the messages put the fact first and the explanation after), without its
    bracketed asides if still too long, and cut at a word with an ellipsis as a last resort."""
    end = _top_level(message, ("; ", ": "))
    return clip(message if end < 0 else message[:end], limit)


def first_clause(text: str) -> str:
    """``text`` up to its first ``, ``, `` to `` or ``; `` outside brackets."""
    end = _top_level(text, (", ", " to ", "; "))
    return text if end < 0 else text[:end]


def clip(text: str, limit: int = SHORT_LIMIT) -> str:
    """``text`` within ``limit`` characters: without its bracketed asides if too long, and cut
    at a word with an ellipsis as a last resort."""
    if len(text) > limit:
        text = _without_brackets(text)
    if len(text) > limit:
        cut = text.rfind(" ", 0, limit - 1)
        text = text[: cut if cut > 0 else limit - 1].rstrip(",;: ") + "\u2026"
    return text


@dataclass(frozen=True, slots=True)
class Finding:
    """One thing a rule found, at one time (or for the whole file when ``time_s`` is None).

    ``message`` is the whole statement (what the docs require, what the profile's PX4 does,
    what the recording shows); ``summary`` the key fact in a few words, for one terminal line.
    A finding without a summary of its own gets its message's first statement."""

    code: str
    name: str
    severity: Severity
    message: str
    time_s: float | None = None
    where: Where | None = None
    vehicle: str = ""
    end_s: float | None = None
    """End of the time window the finding covers, where it covers one."""
    summary: str = ""

    @property
    def short(self) -> str:
        """The summary, or the message's first statement."""
        return self.summary or shorten(self.message)

    def to_json(self) -> dict[str, Any]:
        location: dict[str, Any] | None = None
        if self.where is not None:
            location = {"topic": self.where.topic}
            if self.where.index is not None:
                location["index"] = self.where.index
            if self.where.offset is not None:
                location["offset"] = self.where.offset
        return {
            "code": self.code,
            "name": self.name,
            "severity": self.severity.label,
            "message": self.message,
            "summary": self.short,
            "time_s": None if self.time_s is None else round(self.time_s, 6),
            "end_s": None if self.end_s is None else round(self.end_s, 6),
            "location": location,
            "vehicle": self.vehicle,
        }


@dataclass(frozen=True, slots=True)
class Suppression:
    """Why a finding was taken out of the ones that fail a run: an entry of the
    configuration's ``suppressions`` or the ``--baseline`` file (``kind``)."""

    kind: str
    """``config`` or ``baseline``."""
    reason: str
    source: str
    """The configuration file or the baseline."""
    from_s: float | None = None
    to_s: float | None = None

    def to_json(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "reason": self.reason,
            "source": self.source,
            "from": self.from_s,
            "to": self.to_s,
        }


class RecordingStats(TypedDict, total=False):
    """What a reader counted while it read (``Source.stats``); each format fills its own keys."""

    packets: int
    """tlog: MAVLink packets read."""
    bad_data: int
    """tlog: stretches of bytes that were no packet."""
    bad_data_bytes: int
    unknown: dict[str, int]
    """tlog: packets of message ids the dialect does not know (``UNKNOWN_<id>``, ``other``)."""
    truncated: bool
    messages: int | dict[str, int]
    """MCAP and ROS 2 bags: messages read; tlog: packets per message type."""
    ignored: dict[str, int]
    """tlog: messages read and not used, by reason."""
    messages_decoded: int
    """ROS 1 bags: messages decoded."""
    pyulog_messages: list[str]
    """ULog: what pyulog said about a damaged file (its first lines)."""


class RunStats(TypedDict):
    """What ``engine.run_events`` counted."""

    events: int
    duration_s: float
    vehicles: list[str]
    kinds: dict[str, int]
    """Events per kind."""


class FileStats(RecordingStats, total=False):
    """``FileReport.stats``: the run's counts (``RunStats``), the reader's, and what dates the
    recording (the ``stats`` of the JSON report, spec/interface.md); empty for a file that
    could not be opened."""

    events: int
    duration_s: float
    vehicles: list[str]
    kinds: dict[str, int]
    start_unix_s: float
    notes: list[str]


@dataclass(slots=True)
class FileReport:
    """What linting one recording produced."""

    path: str
    format: str
    profile: Profile
    complete: bool = True
    findings: list[Finding] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    """One line per part of the input that could not be read (OFB001 messages)."""
    malformed: list[str] = field(default_factory=list)
    """One line per malformed part that was read around with nothing lost (OFB004 messages)."""
    stats: FileStats = field(default_factory=lambda: FileStats())
    timelines: dict[str, Timeline] = field(default_factory=dict)
    """Per vehicle, the series the HTML report plots (``engine.lint_file_with_timelines`` fills
    it; empty in a plain lint)."""
    loss_timeouts: dict[str, tuple[float, str]] = field(default_factory=dict)
    """Per vehicle of ``timelines``, the loss timeout the gate used and where it came from."""
    suppressed: list[tuple[Finding, Suppression]] = field(default_factory=list)
    """Findings a suppression took out of ``findings`` (``fuzzoff.suppress``): the reports
    show them apart, and they fail no run."""
    delivery: Delivery | None = None
    """A ROS 2 bag compared with PX4's ULog of the flight (``lint --with``, ``fuzzoff.bridge``)."""

    def to_json(self) -> dict[str, Any]:
        return {
            "path": self.path,
            "format": self.format,
            "profile": {
                "px4": self.profile.px4,
                "vehicle": self.profile.vehicle,
                "detected": self.profile.detected,
                "px4_detected": self.profile.px4_source == "recording",
                "vehicle_detected": self.profile.vehicle_source == "recording",
                "px4_source": self.profile.px4_source,
                "vehicle_source": self.profile.vehicle_source,
                "px4_release": self.profile.px4_release,
                **({"px4_note": self.profile.px4_note} if self.profile.px4_note else {}),
            },
            "complete": self.complete,
            "findings": [f.to_json() for f in self.findings],
            "stats": self.stats,
            **({"delivery": self.delivery.to_json()} if self.delivery is not None else {}),
        }

    def worst(self) -> Severity | None:
        return max((f.severity for f in self.findings), default=None)


@dataclass(slots=True)
class Report:
    """The result of one lint run over one or more recordings."""

    files: list[FileReport] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return all(f.complete for f in self.files)

    @property
    def findings(self) -> list[Finding]:
        return [finding for f in self.files for finding in f.findings]

    def exit_status(self, fail_on: Severity) -> int:
        if not self.complete:
            return 2
        return 1 if any(f.severity >= fail_on for f in self.findings) else 0
