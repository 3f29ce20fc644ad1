"""OFB205: a mode switch to a mode the PX4 release does not have.

Commander reads DO_SET_MODE's main and sub mode (``gate.requests.mode_request``): a main mode
it does not know is acked ACCEPTED with no change up to 1.17 and refused from 1.18; an AUTO
sub-mode it does not know is refused on every release; ALTITUDE_CRUISE exists from 1.17.
"""

from __future__ import annotations

from fuzzoff import releases
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import MAV_CMD_DO_SET_MODE, Command, Event, Where, whole
from fuzzoff.findings import Severity
from fuzzoff.gate.requests import mode_request, unknown_mode_decision
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name


@dataclass(slots=True)
class _Seen:
    params: tuple[int, int, int]
    """base mode, main mode, sub mode"""
    command: Command
    t: float
    where: Where
    last_t: float
    count: int = 1


def _whole_params(cmd: Command) -> tuple[int, int, int]:
    """Base, main and sub mode as whole numbers (-1 for a value that is none: NaN, inf)."""
    base, main, sub = (-1 if (w := whole(p)) is None else w for p in cmd.params[:3])
    return base, main, sub


class ModeNotAvailable(Check):
    codes = ("OFB205",)
    wants = (Command,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.seen: dict[tuple[int, int, int], _Seen] = {}

    def on_event(self, event: Event) -> None:
        if not isinstance(event, Command) or event.command != MAV_CMD_DO_SET_MODE:
            return
        if event.from_external is False:
            return  # PX4's own request (a ULog logs those too)
        key = _whole_params(event)
        seen = self.seen.get(key)
        if seen is None:
            self.seen[key] = _Seen(key, event, event.t, event.where, event.t)
        else:
            seen.last_t = event.t
            seen.count += 1

    def finish(self, t_end: float) -> None:
        for seen in sorted(self.seen.values(), key=lambda s: s.t):
            self._judge(seen)

    def _judge(self, seen: _Seen) -> None:
        profile = self.ctx.profile.release
        nav, problem = mode_request(seen.command, profile)
        base, main, sub = seen.params
        asked = f"DO_SET_MODE base {base}, main {main}, sub {sub}"
        times = f" ({seen.count} times until {seen.last_t:.2f} s)" if seen.count > 1 else ""
        if problem is not None:
            decision = unknown_mode_decision(profile, problem)
            if decision.accepted:
                effect = f"PX4 {profile.name} acks it ACCEPTED and stays in its mode"
            else:
                effect = f"PX4 {profile.name} refuses it (TEMPORARILY_REJECTED)"
            self._report(
                seen,
                Severity.ERROR,
                f"{asked}{times} names no mode: {problem}; {effect}",
                f"mode request for {problem}, which PX4 {profile.name} does not have",
            )
            return
        having = [r.name for r in releases.RELEASES if mode_request(seen.command, r)[1] is None]
        if len(having) == len(releases.RELEASES):
            return
        mode = nav_state_name(nav)
        self._report(
            seen,
            Severity.WARNING,
            f"{asked}{times} asks for {mode}, which PX4 {profile.name} has but releases before "
            f"{having[0]} do not (they ack it with no change or refuse it)",
            f"{mode} exists from PX4 {having[0]} only",
        )

    def _report(self, seen: _Seen, severity: Severity, message: str, short: str) -> None:
        self.ctx.report(
            "OFB205",
            message,
            seen.t,
            seen.where,
            severity=severity,
            end=seen.last_t if seen.count > 1 else None,
            short=short,
        )
