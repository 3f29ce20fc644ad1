"""A stateful search: a companion program built step by step, the gate model checked after each.

``OffboardSession`` is a ``hypothesis.stateful.RuleBasedStateMachine``: its rules are what a
companion does (send keep-alives for a while at a rate, go silent, arm, switch to OFFBOARD,
leave, disarm); after every step the gate model has seen the stream so far, and the invariants
of ``fuzz.invariants`` must hold on it (the known problems of ``fuzz.known`` left out).
Hypothesis shrinks a failing session to the fewest steps. Run it like a test:
``OffboardSession.TestCase().runTest()`` (tests/test_fuzz_campaigns.py).
"""

from __future__ import annotations

import re
from typing import Literal

from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, precondition, rule

from fuzzoff import events as ev
from fuzzoff import releases
from fuzzoff.fuzz.invariants import invariant_violations
from fuzzoff.fuzz.known import KNOWN
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.fuzz.strategies import LOSS_TIMEOUTS, CommandPlan
from fuzzoff.fuzz.streams import commands, settle
from fuzzoff.releases import PX4Profile


class OffboardSession(RuleBasedStateMachine):
    """One ROS 2 companion session against the gate model of one profile."""

    def __init__(self) -> None:
        super().__init__()
        self.px4: PX4Profile = "1.15"
        self.params: dict[str, float] = {}
        self.events: list[ev.Event] = []
        self.now = 0.0

    @initialize(
        px4=st.sampled_from([r.name for r in releases.RELEASES if r.control_mode_flags]),
        timeout=st.sampled_from(LOSS_TIMEOUTS),
    )
    def start(self, px4: PX4Profile, timeout: float) -> None:
        self.px4 = px4
        self.params = {"COM_OF_LOSS_T": timeout}

    @rule(rate=st.sampled_from([2.0, 5.0, 10.0, 50.0]), seconds=st.floats(0.05, 2.0))
    def stream(self, rate: float, seconds: float) -> None:
        """Keep-alive (position) and a trajectory setpoint at ``rate`` for ``seconds``."""
        n = max(1, int(seconds * rate))
        layout: Literal["actuator", "thrust_and_torque"] = (
            "thrust_and_torque"
            if releases.get(self.px4).control_mode == "thrust_and_torque"
            else "actuator"
        )
        for i in range(n):
            t = round(self.now + i / rate, 4)
            stamp = round(t * 1e6)
            self.events.append(
                ev.ControlMode(t=t, position=True, layout=layout, sender_time_us=stamp)
            )
            self.events.append(
                ev.TrajectorySetpoint(
                    t=t + 0.001, position=(0.0, 0.0, -2.0), sender_time_us=stamp + 1000
                )
            )
        self.now = round(self.now + n / rate, 4)

    @rule(seconds=st.floats(0.0, 3.0))
    def silence(self, seconds: float) -> None:
        self.now = round(self.now + seconds, 4)

    @rule(action=st.sampled_from(["arm", "switch", "leave", "disarm"]))
    def command(self, action: str) -> None:
        t = self.now
        plan = CommandPlan(
            arm=t if action == "arm" else None,
            switch=t if action == "switch" else None,
            leave=t if action == "leave" else None,
            disarm=t if action == "disarm" else None,
        )
        self.events += commands(plan, "ros2")
        self.now = round(self.now + 0.01, 4)

    def scenario(self) -> Scenario:
        return Scenario(self.px4, "mc", "ros2", tuple(settle(self.events)), self.params)

    @precondition(lambda self: bool(self.events))
    @invariant()
    def gate_invariants_hold(self) -> None:
        problems = [
            p
            for p in invariant_violations(self.scenario())
            if not any(re.search(k, p) for k in KNOWN)
        ]
        assert not problems, "\n".join(problems)
