"""OFB204: a mode or arming command addressed to no one PX4 is.

PX4's MAVLink receiver checks a command's address before Commander sees it
(``gate.addressing``): a COMMAND_LONG or COMMAND_INT for another system or component, or for
system 0 before 1.18, is answered FAILED (up to 1.15) or dropped without an answer (1.16+); a
SET_MODE for another system is dropped. The tlog reader gives a command to the vehicle its
``target_system`` names, so within one vehicle's events the system is that vehicle's or 0; a
command for a system the recording shows no autopilot of is judged at the end.
"""

from __future__ import annotations

from fuzzoff import releases
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import (
    MAV_CMD_COMPONENT_ARM_DISARM,
    MAV_CMD_DO_SET_MODE,
    Command,
    CommandAck,
    CommandMessage,
    Event,
    Parameter,
    VehicleStatus,
    Where,
)
from fuzzoff.findings import Severity
from fuzzoff.gate.addressing import command_addressing, wrong_address
from fuzzoff.gate.commander import request_name
from fuzzoff.gate.requests import decode_mode
from fuzzoff.lean_dataclass import dataclass

REQUESTS = frozenset({MAV_CMD_DO_SET_MODE, MAV_CMD_COMPONENT_ARM_DISARM})
"""The commands the gate model judges (mode switches, arming and disarming)."""
AUTOPILOT_COMPONENT = 1


@dataclass(slots=True)
class _Seen:
    """Commands alike (one request, one address): the first, the last and how many."""

    request: str
    message: CommandMessage
    system: int
    component: int
    t: float
    where: Where
    last_t: float
    count: int = 1


class CommandTarget(Check):
    codes = ("OFB204",)
    wants = (Command, CommandAck, Parameter, VehicleStatus)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.autopilot_seen = False
        self.seen: dict[tuple[str, str, int, int], _Seen] = {}
        self.verdicts: dict[tuple[str, str, int, int], tuple[Severity, str] | None] = {}

    def on_event(self, event: Event) -> None:
        if event.origin == "vehicle":
            self.autopilot_seen = True
            return
        if not isinstance(event, Command) or event.message is None:
            return  # not a MAVLink message as recorded (a tlog): its address is not known
        if event.origin != "sent" or event.command not in REQUESTS:
            return
        message = event.message
        request = request_name(event, decode_mode(event) if event.is_mode_switch else None)
        key = (request, message, event.target_system, event.target_component)
        seen = self.seen.get(key)
        if seen is None:
            system, component = event.target_system, event.target_component
            self.seen[key] = _Seen(
                request, message, system, component, event.t, event.where, event.t
            )
        else:
            seen.last_t = event.t
            seen.count += 1

    def _component(self) -> int:
        return int(self.ctx.state.params.get("MAV_COMP_ID", AUTOPILOT_COMPONENT))

    def finish(self, t_end: float) -> None:
        ctx = self.ctx
        others = [v for v in ctx.info.vehicles if v.isdigit() and v != ctx.vehicle]
        phantom = not self.autopilot_seen and ctx.vehicle.isdigit() and bool(others)
        for seen in sorted(self.seen.values(), key=lambda s: s.t):
            if phantom and seen.system != 0:
                self._report_phantom(seen, others)
                continue
            verdict = self._verdict(seen)
            if verdict is not None:
                severity, text = verdict
                self._report(seen, severity, text)

    def _command(self, seen: _Seen) -> Command:
        return Command(
            t=seen.t,
            command=MAV_CMD_DO_SET_MODE,
            target_system=seen.system,
            target_component=seen.component,
            message=seen.message,
        )

    def _verdict(self, seen: _Seen) -> tuple[Severity, str] | None:
        """Error where the profile's PX4 does not take the command; warning where it does but
        another modelled release does not; None where every release takes it."""
        own = int(self.ctx.vehicle) if self.ctx.vehicle.isdigit() else None
        component = self._component()
        probe = self._command(seen)
        profile = self.ctx.profile.release
        answer = command_addressing(profile, probe, own, component)
        if not answer.handled:
            change = "the mode" if seen.request.startswith("switch") else "the arming state"
            return Severity.ERROR, f"{answer.effect(profile)}: {change} does not change"
        refused = [
            (r, a)
            for r in releases.RELEASES
            if not (a := command_addressing(r, probe, own, component)).handled
        ]
        if not refused:
            return None
        names = ", ".join(r.name for r, _ in refused)
        return (
            Severity.WARNING,
            f"PX4 {profile.name} handles it, but PX4 {names} do not "
            f"({'; '.join(a.effect(r) for r, a in refused[-1:])}): a client that relies on it "
            "breaks on those releases",
        )

    def _report(self, seen: _Seen, severity: Severity, effect: str) -> None:
        probe = self._command(seen)
        own = int(self.ctx.vehicle) if self.ctx.vehicle.isdigit() else None
        wrong = wrong_address(probe, own, self._component(), broadcast_ok=False)
        times = f" ({seen.count} times until {seen.last_t:.2f} s)" if seen.count > 1 else ""
        self.ctx.report(
            "OFB204",
            f"{seen.message} '{seen.request}' addressed to {wrong}{times}: {effect}",
            seen.t,
            seen.where,
            severity=severity,
            end=seen.last_t if seen.count > 1 else None,
            short=f"{seen.request} addressed to {wrong.split(' (')[0]}",
        )

    def _report_phantom(self, seen: _Seen, others: list[str]) -> None:
        times = f" ({seen.count} times until {seen.last_t:.2f} s)" if seen.count > 1 else ""
        self.ctx.report(
            "OFB204",
            f"{seen.message} '{seen.request}' addressed to system {seen.system}{times}, but "
            f"the recording shows no vehicle with that id (vehicles: {', '.join(others)}): no "
            "PX4 in it acts on the command",
            seen.t,
            seen.where,
            end=seen.last_t if seen.count > 1 else None,
            short=f"{seen.request} for system {seen.system}, which is not in the recording",
        )
