"""Every rule page's test stream replays through the engine: ``bad`` gives that rule, ``good`` not.

The test stream is the rule's behaviour as tiny event lists (``[test_stream]`` in its TOML page,
shown by ``fuzzoff rule CODE --verbose``); the page's Example and Use instead sections show client
code instead. OFB001-OFB004 are about the input and the profile, and OFB006 about the message
definitions a ROS 2 recording carries, and OFB108 about two recordings of one flight (a bag with
PX4's ULog), not about a stream: they are exempt, and listed here so that the exemption is
visible (OFB006's cases are in tests/test_px4_msgs_match.py, OFB108's in tests/test_bridge_with.py).
"""

from __future__ import annotations

from typing import Any

import pytest

from fuzzoff.catalog import Rule, load_catalog
from fuzzoff.config import Settings
from fuzzoff.engine import run_events
from fuzzoff.events import Event, event_from_dict
from fuzzoff.findings import Finding
from fuzzoff.profiles import DEFAULT_PX4, DEFAULT_VEHICLE, Profile
from fuzzoff.recording import RecordingInfo

NOT_STREAM_RULES = {"OFB001", "OFB002", "OFB003", "OFB004", "OFB006", "OFB108"}
"""Rules about reading the file, choosing the profile or the definitions it carries: no event
stream can show them."""

RULES = [rule for code, rule in load_catalog().items() if code not in NOT_STREAM_RULES]


def _replay(rule: Rule, stream: tuple[dict[str, Any], ...]) -> list[Finding]:
    events: list[Event] = sorted((event_from_dict(e) for e in stream), key=lambda e: e.t)
    fmt = rule.formats[0] if rule.formats else "mcap"
    info = RecordingInfo("example", fmt, kinds={e.kind for e in events})
    profile = Profile(
        px4=rule.stream_profile.get("px4", DEFAULT_PX4),
        vehicle=rule.stream_profile.get("vehicle", DEFAULT_VEHICLE),
        px4_detected=True,
        vehicle_detected=True,
    )
    findings, _ = run_events(events, info, profile, Settings())
    return findings


@pytest.mark.parametrize("rule", RULES, ids=[r.code for r in RULES])
def test_bad_test_stream_gives_the_rule(rule: Rule) -> None:
    assert rule.stream_bad, f"rules/{rule.code}.toml has no test_stream.bad"
    found = [f for f in _replay(rule, rule.stream_bad) if f.code == rule.code]
    assert found, f"{rule.code}: test_stream.bad gives no {rule.code} finding"


@pytest.mark.parametrize("rule", RULES, ids=[r.code for r in RULES])
def test_good_test_stream_stays_clean(rule: Rule) -> None:
    assert rule.stream_good, f"rules/{rule.code}.toml has no test_stream.good"
    found = [f for f in _replay(rule, rule.stream_good) if f.code == rule.code]
    assert not found, f"{rule.code}: test_stream.good gives {[f.message for f in found]}"


@pytest.mark.parametrize("rule", RULES, ids=[r.code for r in RULES])
def test_stream_profile_is_one_the_rule_applies_to(rule: Rule) -> None:
    px4 = rule.stream_profile.get("px4", DEFAULT_PX4)
    vehicle = rule.stream_profile.get("vehicle", DEFAULT_VEHICLE)
    assert rule.applies_to(px4, vehicle), f"{rule.code}: test stream profile {px4}/{vehicle}"
