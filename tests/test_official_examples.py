"""The severity principle on the official examples (rules.md "Severity and exit status").

Streams as the examples' sources send them (``tests/official_examples.py``) lint with nothing at
or above the default fail level (warning): what PX4 does with them is what they intend. The same
clients with a hazard planted give its error.
"""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from fuzzoff.config import Settings
from fuzzoff.events import Event
from fuzzoff.findings import Finding, Severity
from tests import official_examples as ex
from tests.streams import codes, lint_events


def failing(findings: Sequence[Finding]) -> list[str]:
    """Findings at or above the default fail level, one line each."""
    fail_on = Settings().fail_on
    return [
        f"{f.code} {f.severity.label} {f.time_s}: {f.message}"
        for f in findings
        if f.severity >= fail_on
    ]


def lint(events: list[Event], px4: str, fmt: str, vehicle: str = "mc") -> list[Finding]:
    return lint_events(events, px4=px4, fmt=fmt, vehicle=vehicle)


@pytest.mark.parametrize("px4", ["1.14", "1.15", "1.16", "1.17"])
def test_px4_ros_com_offboard_control_lints_clean(px4: str) -> None:
    found = lint(ex.px4_ros_com(), px4, "mcap")
    assert failing(found) == []
    # what the docs ask and no release enforces is still said, as info
    (run_up,) = codes(found, "OFB203")
    assert run_up.severity is Severity.INFO and "disarmed" in run_up.message


def test_a_ten_minute_position_hold_lints_clean() -> None:
    found = lint(ex.px4_ros_com(600.0), "1.15", "mcap")
    assert failing(found) == [] and codes(found, "OFB107") == []


@pytest.mark.parametrize("px4", ["1.14", "1.15", "1.16", "1.17"])
def test_mavsdk_offboard_example_lints_clean(px4: str) -> None:
    found = lint(ex.mavsdk_offboard_example(px4), px4, "tlog")
    assert failing(found) == []
    assert codes(found, "OFB107") == []  # its circles are bounded, its straight legs short
    # set_*() then start(): one setpoint before the first switch (the later sections follow
    # without a pause, so their stream is unbroken)
    (start,) = codes(found, "OFB102")
    assert start.severity is Severity.INFO and "accept it" in start.message


def test_mavros_offb_node_example_lints_clean() -> None:
    found = lint(ex.mavros_offb_node(), "1.15", "rosbag1")
    assert failing(found) == []
    assert codes(found, "OFB107") == []  # its hover is a held position


def test_a_px4_ros2_interface_lib_mode_lints_clean() -> None:
    found = lint(ex.px4_ros2_goto(), "1.16", "mcap")
    assert failing(found) == []
    assert codes(found, "OFB203") == []


@pytest.mark.parametrize("px4", ["1.15", "1.16"])
def test_a_first_offboard_descent_after_a_takeoff_lints_clean(px4: str) -> None:
    descent = ex.takeoff_then_offboard(
        px4, (ex.velocity_ned(vz=0.5), 3.0), (ex.velocity_ned(), 10.0)
    )
    found = lint(descent, px4, "tlog")
    assert failing(found) == []


# --- every hazard class stays an error on these clients ------------------------------------


def _errors(findings: Sequence[Finding], code: str) -> list[Finding]:
    return [f for f in codes(findings, code) if f.severity is Severity.ERROR]


def test_a_frozen_motion_command_is_an_error() -> None:
    # a MAVSDK program sets 2 m/s north and dies; the plugin re-sends it for 20 s
    frozen = ex.takeoff_then_offboard("1.16", (ex.velocity_ned(vx=2.0), 20.0))
    found = lint(frozen, "1.16", "tlog")
    (frozen,) = _errors(found, "OFB107")
    assert "velocity 2.00 m/s" in frozen.message


def test_a_stall_mid_air_is_an_error() -> None:
    found = lint(ex.px4_ros_com(stall=(20.0, 21.5)), "1.15", "mcap")
    assert _errors(found, "OFB101") and _errors(found, "OFB103")


def test_enu_height_from_the_ground_is_an_error() -> None:
    found = lint(ex.px4_ros_com(position=(0.0, 0.0, 5.0)), "1.15", "mcap")
    assert _errors(found, "OFB404")


def test_enu_height_after_a_takeoff_is_an_error() -> None:
    up_in_enu = ex.takeoff_then_offboard("1.16", (ex.velocity_ned(), 5.0))
    up_in_enu = [
        e if e.kind != "set_position_target_local_ned" else _as_position(e, 2.5) for e in up_in_enu
    ]
    found = lint(up_in_enu, "1.16", "tlog")
    assert _errors(found, "OFB404")


def _as_position(event: Event, z: float) -> Event:
    from dataclasses import replace

    return replace(event, type_mask=0b110111111000, position=(0.0, 0.0, z))  # type: ignore[type-var]


def test_a_switch_without_stream_while_flying_is_an_error() -> None:
    s = ex.Mavsdk("1.15")
    s.sleep(1.0)
    s.arm()
    s.takeoff()
    s.sleep(10.0)
    s.start()  # no set_*() first: MAVSDK refuses, a hand-written client does not
    found = lint(s.recording(), "1.15", "tlog")
    assert _errors(found, "OFB102")
