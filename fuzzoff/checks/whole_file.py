"""What a recording as a whole says: OFB005 (no offboard in it) and the one OFB002 line that
lists the rules it cannot show.

Both are about the recording, not a vehicle's moment, so the engine asks for them once, after
every vehicle's checks have finished (``recording_findings``). ``OffboardUse`` only watches
whether its vehicle used offboard; the recording gets OFB005 when none did. The rules a
recording cannot show (``CheckContext.cannot_check``) make one OFB002 line, whose message names
each rule with what it would need (``not_checkable_reasons`` reads it back, for JUnit).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace

from fuzzoff.catalog import get_rule
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.checks.outside_offboard import EXTERNAL_MODES
from fuzzoff.config import Settings
from fuzzoff.events import KEEPALIVE_TYPES, Command, Event, VehicleStatus
from fuzzoff.findings import Finding, Severity, shorten
from fuzzoff.gate import GateTransition


class OffboardUse(Check):
    """OFB005's watch: did this vehicle use offboard (recorded or predicted in OFFBOARD or in an
    external mode, px4-ros2-interface-lib's, which the same rules judge, or asked to switch to
    OFFBOARD), and when did its first keep-alive come? It reports nothing itself:
    ``recording_findings`` does, for the whole recording."""

    codes = ("OFB005",)
    wants = (*KEEPALIVE_TYPES, VehicleStatus, Command, GateTransition)

    def on_event(self, event: Event) -> None:
        ctx = self.ctx
        if event is ctx.state.keepalive:
            if ctx.first_keepalive is None:
                ctx.first_keepalive = event.t
        elif not ctx.offboard_used and (
            ctx.in_offboard
            or ctx.gate.in_offboard
            or (isinstance(event, Command) and event.is_offboard_switch)
            or (isinstance(event, VehicleStatus) and event.nav_state in EXTERNAL_MODES)
        ):
            ctx.offboard_used = True

    def on_batch(self, batch: StreamBatch) -> None:
        """Only the first keep-alive matters: the rest of a run changes nothing."""
        if self.ctx.first_keepalive is None:
            keepalives = batch.keepalives()
            if keepalives:
                self.ctx.first_keepalive = keepalives[0].t


NO_OFFBOARD = "no offboard in this recording"


def _no_offboard(contexts: Sequence[CheckContext], settings: Settings) -> Finding:
    """OFB005: the vehicle was never in OFFBOARD and nothing asked for it."""
    several = len(contexts) > 1
    if any(ctx.state.mode_recorded for ctx in contexts):
        who = "no vehicle was ever" if several else "the vehicle was never"
        never = f"{who} in OFFBOARD (its recorded mode) and no switch to it was requested"
    else:
        who = "any vehicle" if several else "the vehicle"
        never = (
            "no switch to OFFBOARD was requested and the gate model never had "
            f"{who} in it (the recording has no mode)"
        )
    sent = [ctx.first_keepalive for ctx in contexts if ctx.first_keepalive is not None]
    message = f"{NO_OFFBOARD}: {never}, so the offboard rules had nothing to judge"
    short = f"{NO_OFFBOARD}: never in OFFBOARD, no switch to it requested"
    if sent:
        message += (
            f"; a stream was sent from {min(sent):.2f} s, but nothing switched to OFFBOARD (a "
            "program that sets setpoints and never starts offboard, or whose switch was not "
            "recorded)"
        )
        short = f"{NO_OFFBOARD}: a stream from {min(sent):.2f} s, no switch"
    return Finding(
        code="OFB005",
        name=get_rule("OFB005").name,
        severity=settings.severity_of("OFB005", Severity.INFO),
        message=message,
        summary=short,
    )


NEEDS = " needs "


def _not_checkable(reasons: dict[str, str], settings: Settings) -> Finding:
    """One OFB002 line for every rule the recording cannot show, each with what it needs (the
    first statement of its reason: the line stays readable with many rules)."""
    codes = sorted(reasons)
    parts = [
        f"{code} ({get_rule(code).name}){NEEDS}"
        + shorten(reasons[code], NEED_LIMIT).removeprefix("needs ")
        for code in codes
    ]
    rules = "1 rule" if len(codes) == 1 else f"{len(codes)} rules"
    return Finding(
        code="OFB002",
        name=get_rule("OFB002").name,
        severity=settings.severity_of("OFB002", Severity.INFO),
        message=f"{rules} cannot be checked on this recording: " + "; ".join(parts),
        summary=f"not checkable here: {', '.join(codes)} (--verbose says what each needs)",
    )


NEED_LIMIT = 150
"""Longest reason a rule gets on the OFB002 line."""

_REASON = re.compile(r"(OFB\d{3}) \([a-z0-9-]+\)" + NEEDS)


def not_checkable_reasons(message: str) -> dict[str, str]:
    """Code -> the rule and what it needs, read back from an OFB002 line ``_not_checkable``
    wrote (JUnit skips each rule with its own reason)."""
    found = list(_REASON.finditer(message))
    ends = [match.start() for match in found[1:]] + [len(message)] if found else []
    return {
        match.group(1): message[match.start() : end].removesuffix("; ")
        for match, end in zip(found, ends, strict=True)
    }


def in_readable_part(finding: Finding) -> Finding:
    """OFB005 of a recording part of which could not be read (OFB001): what it says holds for
    the part that was read only."""
    if finding.code != "OFB005":
        return finding
    return replace(
        finding,
        message=finding.message.replace(
            NO_OFFBOARD, f"{NO_OFFBOARD} (in the part that could be read)", 1
        ),
        summary=finding.summary.replace(NO_OFFBOARD, f"{NO_OFFBOARD} (in the part read)", 1),
    )


def recording_findings(contexts: Sequence[CheckContext], settings: Settings) -> list[Finding]:
    """The findings about the whole recording, once every vehicle's checks have finished."""
    out = []
    reasons: dict[str, str] = {}
    for ctx in contexts:
        for code, needs in ctx.not_checkable.items():
            reasons.setdefault(code, needs)
    if reasons and settings.enabled("OFB002"):
        out.append(_not_checkable(reasons, settings))
    if settings.enabled("OFB005") and not any(ctx.offboard_used for ctx in contexts):
        out.append(_no_offboard(contexts, settings))
    return out
