"""``Settings``: everything that changes what a lint run reports, and the settings one
recording is judged with (``for_recording``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import field, replace
from pathlib import Path
from typing import Any, Protocol

from fuzzoff import releases
from fuzzoff.catalog import get_rule
from fuzzoff.config.globs import FileIgnore
from fuzzoff.findings import Finding, Report, Severity
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.releases import PX4Profile, Release


class Discovery(Protocol):
    """How a command-line run finds each recording's own settings (the nearest configuration
    above it, the command line on top): ``config.discovery.NearestConfig``."""

    def settings_for(self, run: Settings, recording: Path) -> Settings: ...


@dataclass(frozen=True, slots=True)
class ConfigSuppression:
    """One ``suppressions`` entry: findings of ``codes`` in the recordings ``pattern`` names
    (as ``per-file-ignores`` patterns match), starting within ``from_s``..``to_s`` seconds
    (the whole recording when both are None), taken out of the findings that fail a run and
    reported as suppressed, with ``reason``."""

    pattern: str
    folder: str
    codes: frozenset[str]
    reason: str
    source: str
    """The configuration file that holds it."""
    from_s: float | None = None
    to_s: float | None = None

    def matches(self, recording: str | Path) -> bool:
        return FileIgnore(self.pattern, self.folder, self.codes).matches(recording)

    def covers(self, finding: Finding) -> bool:
        """Is ``finding`` one this entry suppresses? A window takes the findings that start in
        it; a whole-recording finding only an entry without a window."""
        if finding.code not in self.codes:
            return False
        if self.from_s is None and self.to_s is None:
            return True
        if finding.time_s is None:
            return False
        low = -math.inf if self.from_s is None else self.from_s
        high = math.inf if self.to_s is None else self.to_s
        return low <= finding.time_s <= high


@dataclass(frozen=True, slots=True)
class Settings:
    """Everything that changes what a lint run reports."""

    px4: PX4Profile | None = None
    """Profile forced by the user (None = detect)."""
    vehicle: str | None = None
    select: frozenset[str] = frozenset()
    """Enabled codes (empty = every rule)."""
    ignore: frozenset[str] = frozenset()
    fail_on: Severity = Severity.WARNING
    severity: Mapping[str, Severity] = field(default_factory=dict)
    options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    params: Mapping[str, float] = field(default_factory=dict)
    config_file: str | None = None
    per_file_ignores: tuple[FileIgnore, ...] = ()
    param_origins: Mapping[str, str] = field(default_factory=dict)
    """Parameter -> where its value was set: ``--param`` or the configuration file's path."""
    notes: tuple[str, ...] = ()
    """What the user should hear about their settings (``--px4 1.12`` is judged as ``1.13``)."""
    discovery: Discovery | None = None
    """Set for a command-line run: each recording then takes its nearest configuration
    (``config.discovery.NearestConfig``)."""
    exit_zero: bool = False
    """``--exit-zero`` or ``fail-on = "never"``: findings never make the exit status 1 (the
    reports still judge them at ``fail_on``); input that could not be read still gives 2."""
    suppressions: tuple[ConfigSuppression, ...] = ()

    def exit_status(self, report: Report) -> int:
        """The run's exit status: 0 passed, 1 findings at or above ``fail_on`` (never with
        ``exit_zero``), 2 input not read completely."""
        status = report.exit_status(self.fail_on)
        return 0 if status == 1 and self.exit_zero else status

    def enabled(self, code: str) -> bool:
        if code in self.ignore:
            return False
        return not self.select or code in self.select

    def option(self, code: str, name: str) -> Any:
        """A rule threshold: the user's value, else the catalog default."""
        value = self.options.get(code, {}).get(name)
        if value is not None:
            return value
        return get_rule(code).option(name).default

    def severity_of(self, code: str, default: Severity) -> Severity:
        return self.severity.get(code, default)

    def param_origin(self, name: str) -> str:
        """How a report words where a parameter set by the user came from."""
        origin = self.param_origins.get(name)
        if origin is None:
            return "set by the user"  # Settings(params=...) from the Python API
        if origin == "--param":
            return "set with --param"
        return f"set in {Path(origin).name}"

    @property
    def release(self) -> Release | None:
        """The record of the ``--px4`` profile (None: detect from each recording). ``px4`` was
        resolved once, when the settings were read; this only looks the record up."""
        return None if self.px4 is None else releases.get(self.px4)

    def resolved_for(self, recording: str | Path) -> Settings:
        """``for_recording``, resolved once: a lint given these settings does not look for a
        configuration again (no ``discovery`` left to follow); the per-file ignores it applies
        again add nothing."""
        return replace(self.for_recording(recording), discovery=None)

    def for_recording(self, recording: str | Path) -> Settings:
        """The settings one recording is judged with: its nearest configuration (for a
        command-line run), the command line on top, then the ``per-file-ignores`` it matches."""
        settings = self
        if self.discovery is not None:
            settings = self.discovery.settings_for(self, Path(recording))
        ignored = frozenset(
            code
            for rule in settings.per_file_ignores
            if rule.matches(recording)
            for code in rule.codes
        )
        if ignored - settings.ignore:
            settings = replace(settings, ignore=settings.ignore | ignored)
        mine = tuple(s for s in settings.suppressions if s.matches(recording))
        if mine != settings.suppressions:
            settings = replace(settings, suppressions=mine)
        return settings
