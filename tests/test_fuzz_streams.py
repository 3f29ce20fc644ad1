"""The generated streams: what the strategies draw is what a recording of it can hold and what
a real PX4 can be sent."""

from __future__ import annotations

import math

from hypothesis import given, settings

from fuzzoff.events import RoverSteeringSetpoint
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.fuzz.streams import scenarios


@settings(max_examples=30, database=None, deadline=None, derandomize=True)
@given(scenarios(px4="1.17", vehicle="rover-ackermann", transport="ros2"))
def test_a_1_17_rover_stream_sends_only_what_its_messages_carry(scenario: Scenario) -> None:
    """1.17 dropped ``RoverSteeringSetpoint.normalized_speed_diff``: a generated stream that
    set it could not be written (its MCAP read back NaN, and the round trip of seed 3 failed)."""
    for e in scenario.events:
        if isinstance(e, RoverSteeringSetpoint):
            assert math.isnan(e.normalized_speed_diff)
