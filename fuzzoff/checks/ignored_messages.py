"""OFB608: MAVLink setpoint messages the profile's PX4 has no handler for.

PX4 1.14 removed the MAVLink receiver's handler of ``SET_ACTUATOR_CONTROL_TARGET`` (#139,
gate.md#receiver): MAVSDK's ``set_actuator_control`` and MAVROS ``actuator_control`` still
send it (two groups at MAVSDK's 20 Hz: 40 messages a second), and PX4 ignores every one: no
setpoint, no keep-alive. The rule's profiles (1.14+) say where; on 1.13 and older PX4 handles
the message.

The keep-alive rules see what this leaves: OFB101 the gap in the keep-alive (and how many of
these messages came in it), OFB103 the loss failsafe, OFB102 and OFB201 a switch refused for
want of a keep-alive. This rule names the messages themselves, once per stretch.
"""

from __future__ import annotations

from fuzzoff.catalog import get_rule
from fuzzoff.checks._episodes import MERGE_GAP_S
from fuzzoff.checks._keepalive import px4_label
from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import Event, SetActuatorControlTarget
from fuzzoff.lean_dataclass import dataclass

IGNORED: tuple[type[Event], ...] = (SetActuatorControlTarget,)
"""The messages a release of OFB608's profiles has no handler for."""

MESSAGE_NAMES: dict[type[Event], str] = {SetActuatorControlTarget: "SET_ACTUATOR_CONTROL_TARGET"}


def ignores(ctx: CheckContext) -> bool:
    """Does the profile's PX4 ignore the ``IGNORED`` messages (OFB608's profiles)?"""
    return get_rule("OFB608").applies_to(ctx.profile.px4, ctx.profile.vehicle)


def message_name(event: Event) -> str:
    return MESSAGE_NAMES[type(event)]


@dataclass(slots=True)
class _Stretch:
    """Messages of one kind, each less than ``MERGE_GAP_S`` after the one before."""

    first: Event
    last_t: float
    count: int = 1
    in_offboard: int = 0


class IgnoredMessages(Check):
    """OFB608: each stretch of messages PX4 ignores, with how many and what it means."""

    codes = ("OFB608",)
    wants = IGNORED

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.open: dict[str, _Stretch] = {}

    def on_event(self, event: Event) -> None:
        if event.origin != "sent" or not isinstance(event, IGNORED):
            return
        stretch = self.open.get(event.kind)
        if stretch is not None and event.t - stretch.last_t > MERGE_GAP_S:
            self._report(stretch)
            stretch = None
        if stretch is None:
            stretch = self.open[event.kind] = _Stretch(event, event.t, count=0)
        stretch.last_t = event.t
        stretch.count += 1
        if self.ctx.in_offboard:
            stretch.in_offboard += 1

    def _report(self, stretch: _Stretch) -> None:
        name = message_name(stretch.first)
        px4 = px4_label(self.ctx)
        first = stretch.first
        many = f"{stretch.count} {name}"
        if stretch.count > 1:
            many += f" from {first.t:.2f} to {stretch.last_t:.2f} s"
        if stretch.in_offboard:
            many += f" ({stretch.in_offboard} in OFFBOARD)"
        message = (
            f"{many}: {px4} has no handler for this message (removed in PX4 1.14) and ignores "
            "every one: no setpoint, no keep-alive; sent alone, the offboard signal is never "
            "there (a switch to OFFBOARD is refused: OFB102, OFB201) or is lost (OFB101, "
            "OFB103); direct actuator control is ROS 2's (ActuatorMotors and ActuatorServos "
            "with OffboardControlMode.direct_actuator)"
        )
        short = f"{stretch.count} {name} ignored by {px4}: no setpoint, no keep-alive"
        end = stretch.last_t if stretch.count > 1 else None
        self.ctx.report("OFB608", message, first.t, first.where, end=end, short=short)

    def finish(self, t_end: float) -> None:
        for stretch in self.open.values():
            self._report(stretch)
        self.open.clear()
