"""Findings, severities, and the per-file report the engine returns."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any

from fuzzoff.events import Where
from fuzzoff.profiles import Profile


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


@dataclass(frozen=True, slots=True)
class Finding:
    """One thing a rule found, at one time (or for the whole file when ``time_s`` is None)."""

    code: str
    name: str
    severity: Severity
    message: str
    time_s: float | None = None
    where: Where | None = None
    vehicle: str = ""
    end_s: float | None = None
    """End of the time window the finding covers, where it covers one."""

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
            "time_s": None if self.time_s is None else round(self.time_s, 6),
            "end_s": None if self.end_s is None else round(self.end_s, 6),
            "location": location,
            "vehicle": self.vehicle,
        }


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
    stats: dict[str, Any] = field(default_factory=dict)
    extras: dict[str, Any] = field(default_factory=dict)
    """Optional data for rich reports (gate timeline, keep-alive series)."""

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
            },
            "complete": self.complete,
            "findings": [f.to_json() for f in self.findings],
            "stats": self.stats,
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
