"""The check protocol: a small state machine that sees one vehicle's events in order.

A check subclasses ``Check``, names the rule codes it can report (``codes``) and the event
types it wants (``wants``; ``GateTransition`` included for checks driven by the gate model),
and reports through ``self.ctx.report``. Subclassing registers it; a module in this package
is imported automatically, so adding a rule needs no edit elsewhere.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

from fuzzoff.catalog import get_rule
from fuzzoff.config import Settings
from fuzzoff.events import Event, Where
from fuzzoff.findings import Finding, Severity
from fuzzoff.gate import GateModel
from fuzzoff.profiles import Profile
from fuzzoff.sources.base import RecordingInfo
from fuzzoff.state import VehicleState
from fuzzoff.tables.control_mode import FlagRow, row_for

REGISTRY: list[type[Check]] = []


@dataclass(slots=True)
class CheckContext:
    """Everything a check may read, and where it reports. One per vehicle per recording."""

    profile: Profile
    settings: Settings
    info: RecordingInfo
    vehicle: str
    state: VehicleState
    gate: GateModel
    findings: list[Finding] = field(default_factory=list)
    not_checkable: dict[str, str] = field(default_factory=dict)
    """code -> what the recording would need (becomes one OFB002 finding per code)."""
    _rows: dict[str | None, FlagRow | None] = field(default_factory=dict)

    def row_for(self, first_flag: str | None) -> FlagRow | None:
        """``tables.control_mode.row_for`` for this profile, remembered per flag: the content
        rules ask on every setpoint, and the table lookup compares version strings (~1 µs)."""
        try:
            return self._rows[first_flag]
        except KeyError:
            row = self._rows[first_flag] = row_for(self.profile, first_flag)
            return row

    def enabled(self, code: str) -> bool:
        try:
            rule = get_rule(code)
        except KeyError:  # a check without a catalog page never reports (a test catches it)
            return False
        return self.settings.enabled(code) and rule.applies_to(
            self.profile.px4, self.profile.vehicle
        )

    def option(self, code: str, name: str) -> Any:
        return self.settings.option(code, name)

    def report(
        self,
        code: str,
        message: str,
        t: float | None,
        where: Where | None = None,
        *,
        severity: Severity | None = None,
        end: float | None = None,
    ) -> None:
        """Record a finding. ``severity`` lowers or raises the catalog default for this case
        (e.g. a docs rule the profile's PX4 tolerates); the user's override wins over both."""
        if not self.enabled(code):
            return
        rule = get_rule(code)
        level = self.settings.severity_of(code, severity if severity is not None else rule.severity)
        self.findings.append(
            Finding(
                code=code,
                name=rule.name,
                severity=level,
                message=message,
                time_s=t,
                where=where,
                vehicle=self.vehicle,
                end_s=end,
            )
        )

    def cannot_check(self, code: str, needs: str) -> None:
        """Say once that ``code`` cannot be judged here and what the recording would need."""
        if self.enabled(code):
            self.not_checkable.setdefault(code, needs)

    def has(self, *kinds: str) -> bool:
        """Does the recording carry any of these event kinds at all?"""
        return any(kind in self.info.kinds for kind in kinds)


class Check:
    codes: ClassVar[tuple[str, ...]] = ()
    wants: ClassVar[tuple[type[Event], ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if cls.codes:
            REGISTRY.append(cls)

    def __init__(self, ctx: CheckContext) -> None:
        self.ctx = ctx
        self.subscriptions: tuple[type[Event], ...] = self.wants
        """What the engine sends this instance; a check that finds in ``__init__`` that the
        recording cannot show its rule sets it to ``()`` and costs nothing per message."""

    @classmethod
    def wanted(cls, ctx: CheckContext) -> bool:
        """Instantiate only if one of its codes is enabled and applies to the profile."""
        return any(ctx.enabled(code) for code in cls.codes)

    def on_event(self, event: Event) -> None:
        """Called for every event whose type is in ``wants``, in time order."""

    def finish(self, t_end: float) -> None:
        """Called once after the last event (``t_end`` = the recording's last time)."""


Handler = Callable[[Event], None]
