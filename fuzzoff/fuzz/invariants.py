"""Invariants of the gate model (docs/fuzz.md), checked on the gate model running over a
scenario's sent stream.

0. The model's timeline never goes back in time (transitions in time order).
1. No OFFBOARD while the signal is lost, armed, on 1.14+ (5.1), longer than one Commander
   iteration after the loss, unless the loss action changes no mode (Disarm, none).
2. The loss is never declared earlier than the loss timeout after the newest keep-alive
   (2.1: ``now - ts >= COM_OF_LOSS_T``; 2.2 hysteresis; 2.3 legacy 500 ms), for a stream whose
   keep-alives all count (ROS 2 control modes with a flag; MAVLink with nothing dropped). On
   1.14+ a ROS 2 control mode dates from its ``timestamp`` as PX4 rewrites it (2.1.1), which a
   late delivery leaves older than its arrival.
3. After a loss failsafe, the first time the signal is available again the vehicle is back in
   OFFBOARD, unless a mode or arming command came in between or the action was Terminate or
   Disarm (5.1 recovery, 5.2, 5.3).
4. On 1.14+, a switch to OFFBOARD while disarmed is accepted (4.1), stream or not (SET_NAV_STATE
   only from 1.15).

Only the events the stream sends are fed (the vehicle's answers re-synchronise the model to a
recording, which is not what is checked here).
"""

from __future__ import annotations

import itertools

from fuzzoff.events import (
    NAV_STATE_OFFBOARD,
    VEHICLE_CMD_SET_NAV_STATE,
    Command,
    ControlMode,
    Event,
)
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.gate import GateModel, GateTransition
from fuzzoff.gate.signal import LOOP_PERIOD, px4_stamp

EPS = 1e-6
TERMINATION = 13


def invariant_violations(scenario: Scenario) -> list[str]:
    # The scenario's vehicle boots disarmed (its stream starts from there).
    model = GateModel(scenario.profile, dict(scenario.params), _vehicle(scenario), armed=False)
    sent = [e for e in scenario.events if e.origin == "sent"]
    release = scenario.profile.release
    problems: list[str] = []
    transitions: list[GateTransition] = []
    last_keepalive: float | None = None
    all_count = True
    lost_since: float | None = None
    dating = _Dating(release.ros2_timestamp_rewrite)
    for event in sent:
        before_armed, before_nav = model.armed, model.nav_state
        out = model.feed(event)
        for tr in out:
            transitions.append(tr)
            if tr.what == "signal_lost":
                lost_since = tr.t
                problems += _early_loss(scenario, tr, last_keepalive, all_count)
            elif tr.what == "signal_available":
                lost_since = None
            elif tr.what == "setpoint_dropped":
                all_count = False
        if _is_counted_keepalive(event):
            last_keepalive = dating.dated(event)
        elif isinstance(event, ControlMode):
            all_count = False  # an empty control mode is a keep-alive that does not count
        if (
            release.loss_failsafe == "framework"
            and model.armed
            and model.in_offboard
            and lost_since is not None
            and event.t - lost_since > LOOP_PERIOD + EPS
            and model.current_loss_action().nav_state is not None
        ):
            problems.append(
                f"invariant 1 (5.1): OFFBOARD at {event.t:.3f} s while armed with the signal "
                f"lost since {lost_since:.3f} s"
            )
        if (
            isinstance(event, Command)
            and event.is_offboard_switch
            and release.accepts_disarmed_switch
        ):
            problems += _disarmed_switch(scenario, event, out, before_armed, before_nav)
    end = sent[-1].t if sent else 0.0
    transitions += model.finish(end)
    problems += _in_time_order(transitions)
    problems += _resumes(scenario, transitions, sent)
    return problems[:3]


def _in_time_order(transitions: list[GateTransition]) -> list[str]:
    for a, b in itertools.pairwise(transitions):
        if b.t < a.t - EPS:
            return [
                f"invariant 0: the model's timeline goes back in time: {a.what} at {a.t:.3f} s "
                f"({a.message}) is followed by {b.what} at {b.t:.3f} s ({b.message})"
            ]
    return []


def _vehicle(scenario: Scenario) -> str:
    return "1" if scenario.transport == "mavlink" else ""


class _Dating:
    """When PX4 dates a keep-alive: its receive time, except a ROS 2 control mode on 1.14+,
    dated by its ``timestamp`` (2.1.1; the sender's clock offset taken from the first stamped
    one, which counts as fresh, as the model takes it)."""

    def __init__(self, stamped: bool) -> None:
        self.stamped = stamped
        self.offset: float | None = None

    def dated(self, event: Event) -> float:
        sender_us = event.sender_time_us
        if not (self.stamped and isinstance(event, ControlMode) and sender_us):
            return event.t
        if self.offset is None:
            self.offset = sender_us * 1e-6 - event.t
        return px4_stamp(event.t, sender_us, self.offset)


def _is_counted_keepalive(event: Event) -> bool:
    if isinstance(event, ControlMode):
        return bool(event.flags())
    return event.kind.startswith("set_")


def _early_loss(
    scenario: Scenario, tr: GateTransition, last: float | None, all_count: bool
) -> list[str]:
    if tr.reason != "keep-alive timeout" or last is None or not all_count:
        return []
    from fuzzoff.gate.params import default_params, loss_timeout

    timeout = loss_timeout(scenario.px4, default_params(scenario.px4) | dict(scenario.params))
    if tr.t - last < timeout - EPS:
        return [
            f"invariant 2 (2.1-2.3): signal lost at {tr.t:.3f} s, {tr.t - last:.3f} s after the "
            f"newest keep-alive ({last:.3f} s), before the loss timeout {timeout:g} s"
        ]
    return []


def _disarmed_switch(
    scenario: Scenario,
    cmd: Command,
    out: list[GateTransition],
    was_armed: bool | None,
    nav: int | None,
) -> list[str]:
    if was_armed or nav == TERMINATION:
        return []
    release = scenario.profile.release
    if cmd.command == VEHICLE_CMD_SET_NAV_STATE and not release.handles_set_nav_state:
        return []
    if any(tr.what == "request_accepted" and tr.cause is cmd for tr in out):
        return []
    return [f"invariant 4 (4.1): switch to OFFBOARD at {cmd.t:.3f} s while disarmed not accepted"]


def _resumes(scenario: Scenario, transitions: list[GateTransition], sent: list[Event]) -> list[str]:
    commands = [e.t for e in sent if isinstance(e, Command)]
    problems = []
    for i, tr in enumerate(transitions):
        if tr.what != "failsafe" or tr.action in ("TERMINATE", "DISARM", "NONE"):
            continue
        if tr.nav_state in (TERMINATION, None):
            continue
        back = next((b for b in transitions[i + 1 :] if b.what == "signal_available"), None)
        if back is None:
            continue
        if any(tr.t - EPS <= t <= back.t + EPS for t in commands):
            continue
        if not back.armed:
            continue
        later = [x for x in transitions if abs(x.t - back.t) <= LOOP_PERIOD + EPS]
        if not any(
            x.nav_state == NAV_STATE_OFFBOARD and x.what == "offboard_resumed" for x in later
        ):
            problems.append(
                f"invariant 3 (5): signal back at {back.t:.3f} s after the failsafe at "
                f"{tr.t:.3f} s, but no return to OFFBOARD"
            )
    return problems
