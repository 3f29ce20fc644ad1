"""Simpler variants of a stream that PX4 and the gate model disagreed on (live shrinking).

Hypothesis shrinks by running hundreds of examples; a live example takes 10-60 s of real time,
so a live campaign shrinks by hand instead: each variant below is sent once, in this order, and
kept when PX4 and the model still disagree the same way; a few runs per disagreement at most.
The ones most likely to keep the disagreement come first:

1. ``cut``: nothing after the disagreement (what PX4 did then cannot depend on it);
2. ``plain setpoints``: every setpoint a LOCAL_NED position hold (the content did not matter);
3. ``thinned to 10 Hz``: setpoints less than 0.1 s after the one kept before dropped, but both
   ends of every gap of 0.1 s or more kept (the gaps the loss timeout is about stay as they
   were);
4. ``without <command>``: each command before the disagreement dropped in turn (a disarm and a
   leave first, the switch last).

The vehicle's side of a variant (its COMMAND_ACKs in the reproducer) is the gate model's
prediction for the variant's commands, as the campaign's streams have it (``streams.echo``).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import replace

from fuzzoff import events as ev
from fuzzoff.fuzz.scenario import AUTOPILOT, COMPANION, Scenario
from fuzzoff.fuzz.streams import echo, settle

PLAIN_TYPE_MASK = 0x0DF8
"""Position only (velocity, acceleration, yaw and yaw rate ignored)."""
PLAIN_POSITION = (0.0, 0.0, -2.5)
THIN_PERIOD_S = 0.1
CUT_AFTER_S = 0.2
"""A cut keeps this much after the disagreement (the messages PX4 got as it decided)."""
DROP_ORDER = ("disarm", "leave", "arm", "switch")


def sent_side(scenario: Scenario) -> list[ev.Event]:
    """The companion's events: what a live run sends."""
    return [e for e in scenario.events if isinstance(e, ev.Command | ev.MavlinkTarget)]


def rebuild(scenario: Scenario, sent: Sequence[ev.Event]) -> Scenario:
    """``scenario`` with ``sent`` as its companion side and the model's answers to it."""
    acks = any(isinstance(e, ev.CommandAck) for e in scenario.events)
    ordered = settle(sent, from_zero=False)
    answers = echo(
        ordered,
        scenario.px4,
        scenario.vehicle,
        dict(scenario.params),
        acks=acks,
        status=False,
        transport="mavlink",
    )
    stream = settle([*ordered, *answers], from_zero=False)
    return replace(scenario, events=tuple(stream))


def label(cmd: ev.Command) -> str:
    if cmd.is_arm:
        return "arm"
    if cmd.is_disarm:
        return "disarm"
    if cmd.is_offboard_switch:
        return "switch"
    return "leave" if cmd.is_mode_switch else f"command {cmd.command}"


def variants(scenario: Scenario, t: float) -> Iterator[tuple[str, Scenario]]:
    """Simpler variants of ``scenario`` whose disagreement was at stream time ``t``, in the
    order to try them; each differs from ``scenario``. The caller tries them one at a time,
    keeps the first that still disagrees and asks again from it (a name once tried is not
    tried again)."""
    sent = sent_side(scenario)
    kept = [e for e in sent if e.t <= t + CUT_AFTER_S]
    if 0 < len(kept) < len(sent):
        yield f"cut after {t + CUT_AFTER_S:.2f} s", rebuild(scenario, kept)
    setpoints = [e for e in sent if isinstance(e, ev.MavlinkTarget)]
    if any(not _is_plain(e) for e in setpoints):
        yield (
            "plain setpoints",
            rebuild(scenario, [_plain(e) if isinstance(e, ev.MavlinkTarget) else e for e in sent]),
        )
    thinned = _thinned(setpoints)
    if len(thinned) < len(setpoints):
        keep = {id(e) for e in thinned}
        yield (
            "thinned to 10 Hz",
            rebuild(
                scenario, [e for e in sent if not isinstance(e, ev.MavlinkTarget) or id(e) in keep]
            ),
        )
    commands = [e for e in sent if isinstance(e, ev.Command) and e.t < t - 0.05]
    order = {name: i for i, name in enumerate(DROP_ORDER)}
    commands.sort(key=lambda c: order.get(label(c), -1))
    for cmd in commands:
        yield (
            f"without the {label(cmd)} at {cmd.t:.2f} s",
            rebuild(scenario, [e for e in sent if e is not cmd]),
        )


def _thinned(setpoints: Sequence[ev.Event]) -> list[ev.Event]:
    """At most one setpoint per 0.1 s, keeping both ends of every gap of 0.1 s or more."""
    out: list[ev.Event] = []
    for i, e in enumerate(setpoints):
        follows = setpoints[i + 1].t - e.t if i + 1 < len(setpoints) else None
        if (
            not out
            or e.t - out[-1].t >= THIN_PERIOD_S - 1e-6
            or follows is None
            or follows >= THIN_PERIOD_S - 1e-6
        ):
            out.append(e)
    return out


def _is_plain(e: ev.MavlinkTarget) -> bool:
    return (
        isinstance(e, ev.SetPositionTargetLocal)
        and e.coordinate_frame == 1
        and e.type_mask == PLAIN_TYPE_MASK
        and e.position == PLAIN_POSITION
    )


def _plain(e: ev.MavlinkTarget) -> ev.SetPositionTargetLocal:
    return ev.SetPositionTargetLocal(
        t=e.t,
        vehicle=e.vehicle,
        sender_time_us=e.sender_time_us,
        target_system=AUTOPILOT[0],
        target_component=AUTOPILOT[1],
        source_system=COMPANION[0],
        source_component=COMPANION[1],
        coordinate_frame=1,
        type_mask=PLAIN_TYPE_MASK,
        position=PLAIN_POSITION,
        velocity=(0.0, 0.0, 0.0),
        acceleration=(0.0, 0.0, 0.0),
    )
