"""Replay a tlog's companion stream to a live PX4 as a real client would.

The recording's autopilot messages are its answers, not part of the stream; its HEARTBEATs from
others are replaced by the client's own. Every other message the companion (or a ground
station) sent is decoded by pymavlink and sent again *from the client* (its own sysid and
component), with its ``target_system``/``target_component`` set to the autopilot the client
hears: a recording made with sysid 1, or a reproducer whose commands address system 0, reaches
PX4's gate instead of being dropped or refused with FAILED.

Timing is PX4's clock: message ``i`` goes out when PX4's clock has moved ``t_i / speed`` since
the first one (``Link.sleep_until``), so a 1.0 s gap is 1.0 s where the gate measures it.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import field
from pathlib import Path
from typing import Any

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.mavlink_ids import MAV_AUTOPILOT_PX4
from fuzzoff.modes import nav_state_name
from fuzzoff.recording import SourceError
from fuzzoff.sitl.link import Link, LinkError, open_tlog

NAV_OFFBOARD = 14
SKIPPED = frozenset({"HEARTBEAT", "TIMESYNC", "SYSTEM_TIME"})
"""Link housekeeping of the recorded client: the live client sends its own."""


@dataclass(slots=True)
class Plan:
    """What a replay sends and the state the recording starts in."""

    messages: list[tuple[float, Any]] = field(default_factory=list)
    """(seconds from the first sent message, the decoded message)."""
    start_nav: int | None = None
    start_armed: bool | None = None
    autopilot: tuple[int, int] | None = None
    skipped: Counter[str] = field(default_factory=Counter)
    damaged_at: int | None = None
    """Byte offset of the first packet pymavlink could not read (None: the tlog is whole)."""

    @property
    def duration(self) -> float:
        return self.messages[-1][0] if self.messages else 0.0

    def start_text(self) -> str:
        if self.start_nav is None and self.start_armed is None:
            return "not recorded"
        arming = {None: "", True: " armed", False: " disarmed"}[self.start_armed]
        return f"{nav_state_name(self.start_nav)}{arming}"


def plan_from_tlog(path: Path) -> Plan:
    """The companion's messages of ``path`` and the autopilot's state before the first one
    (``SourceError`` when pymavlink cannot read it as a tlog)."""
    from fuzzoff.modes import custom_mode_to_nav_state

    plan = Plan()
    first: float | None = None
    try:
        log = open_tlog(path)
    except OSError as exc:
        raise SourceError(str(path), f"cannot open: {exc.strerror or exc}") from None
    end = 0
    try:
        while True:
            offset = log.f.tell()
            msg = log.recv_msg()
            if msg is None:
                if end < path.stat().st_size and plan.damaged_at is None:
                    plan.damaged_at = end  # the file ends inside a record: cut short
                break
            end = log.f.tell()
            kind = msg.get_type()
            if kind == "BAD_DATA":
                if plan.damaged_at is None:
                    plan.damaged_at = offset
                continue
            sender = (msg.get_srcSystem(), msg.get_srcComponent())
            if kind == "HEARTBEAT" and msg.autopilot == MAV_AUTOPILOT_PX4 and sender[1] == 1:
                plan.autopilot = plan.autopilot or sender
                if sender == plan.autopilot and not plan.messages:
                    plan.start_nav = custom_mode_to_nav_state(msg.custom_mode)
                    plan.start_armed = bool(msg.base_mode & 128)
                continue
            if plan.autopilot is not None and sender == plan.autopilot:
                continue
            if sender[1] == 1 and sender[0] == (plan.autopilot or (1, 1))[0]:
                continue  # the autopilot's messages before its first HEARTBEAT
            if kind in SKIPPED or kind.startswith("UNKNOWN"):
                plan.skipped[kind] += 1
                continue
            stamp = float(msg._timestamp)
            first = stamp if first is None else first
            plan.messages.append((stamp - first, msg))
    except (ValueError, IndexError) as exc:
        raise SourceError(str(path), f"not a readable tlog: {exc}") from None
    finally:
        log.close()
    return plan


def readdress(msg: Any, target: tuple[int, int]) -> Any:
    """The message addressed to ``target`` (fields it has: target_system, target_component)."""
    names = msg.get_fieldnames()
    if "target_system" in names:
        msg.target_system = target[0]
    if "target_component" in names:
        msg.target_component = target[1]
    return msg


def bring_to_start(link: Link, plan: Plan) -> list[str]:
    """Put PX4 in the recording's starting state where it can; what it did or could not do
    (``LinkError`` when PX4 refused a step the recording's outcome depends on)."""
    notes: list[str] = []
    view = link.view
    if plan.start_nav is None and plan.start_armed is None:
        now = f"{nav_state_name(view.nav_state)}, {'armed' if view.armed else 'disarmed'}"
        return [f"the recording does not show its starting state: replayed from PX4's ({now})"]
    if plan.start_armed and plan.start_nav == NAV_OFFBOARD:
        raise LinkError(
            "the recording starts armed in OFFBOARD (already flying offboard): a replay cannot"
            " bring PX4 there before its stream"
        )
    if plan.start_nav is not None and view.nav_state != plan.start_nav:
        ack = link.set_mode(plan.start_nav)
        if ack is None or ack.result != 0:
            raise LinkError(
                "cannot bring PX4 to the starting mode of the recording, "
                f"{nav_state_name(plan.start_nav)}"
                f" ({'no ack' if ack is None else f'ack {ack.result}'})"
            )
        notes.append(f"starting mode {nav_state_name(plan.start_nav)} set")
    if plan.start_armed and not view.armed:
        ack = link.arm(True)
        if ack is None or ack.result != 0:
            raise LinkError(
                "cannot arm PX4 as the recording starts armed"
                f" ({'no ack' if ack is None else f'ack {ack.result}'})"
            )
        notes.append("armed, as the recording starts")
    elif plan.start_armed is False and view.armed:
        raise LinkError("PX4 is armed but the recording starts disarmed: land and disarm first")
    return notes


def send(
    link: Link, plan: Plan, speed: float = 1.0, tick: Callable[[], None] | None = None
) -> list[float]:
    """Send the plan's messages on PX4's clock; the PX4 time each one went out (what the
    tlog records for it). ``tick`` runs while waiting (a joystick beside the stream)."""
    target = link.target
    start = link.clock.now()
    sent = []
    for t, msg in plan.messages:
        link.sleep_until(start + t / speed, tick)
        link.send(readdress(msg, target))
        sent.append(link.clock.now())
    return sent
