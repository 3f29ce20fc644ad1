"""The pass collects garbage less often, and gives a library caller its own settings back."""

from __future__ import annotations

import gc
from collections.abc import Iterable, Iterator

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import YOUNG_COLLECTION_EVERY, run_events
from fuzzoff.events import Event
from fuzzoff.findings import Finding
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from tests.streams import OFFBOARD, codes, every, ocm, status

Thresholds = tuple[int, int, int]


def _flight() -> list[Event]:
    """Armed in OFFBOARD with a 1.5 s hole in the keep-alive (an OFB101 finding)."""
    return [status(0.0, OFFBOARD), *ocm(every(0.0, 2.0, 0.1)), *ocm([3.5, 3.6])]


def _watched(events: Iterable[Event], seen: list[Thresholds]) -> Iterator[Event]:
    """The events, noting the collector's thresholds while the engine reads them."""
    for event in events:
        seen.append(gc.get_threshold())
        yield event


def _run(events: Iterable[Event]) -> list[Finding]:
    info = RecordingInfo("stream", "mcap", kinds={"vehicle_status", "control_mode"})
    profile = Profile(px4="1.15", vehicle="mc", px4_detected=True, vehicle_detected=True)
    findings, _ = run_events(events, info, profile, Settings())
    return findings


@pytest.fixture(autouse=True)
def _callers_thresholds() -> Iterator[None]:
    before = gc.get_threshold()
    yield
    gc.set_threshold(*before)


def test_the_pass_collects_less_often_and_gives_the_thresholds_back() -> None:
    gc.set_threshold(700, 10, 10)
    seen: list[Thresholds] = []
    findings = _run(_watched(_flight(), seen))
    assert codes(findings, "OFB101"), "the findings are those of any pass"
    assert set(seen) == {(YOUNG_COLLECTION_EVERY, 10, 10)}
    assert gc.get_threshold() == (700, 10, 10)


def test_thresholds_come_back_when_the_reader_fails_mid_pass() -> None:
    gc.set_threshold(700, 10, 10)

    def failing() -> Iterator[Event]:
        yield from _flight()[:5]
        raise OSError("disk gone")

    with pytest.raises(OSError):
        _run(failing())
    assert gc.get_threshold() == (700, 10, 10)


@pytest.mark.parametrize("callers", [(0, 10, 10), (100_000, 5, 5)])
def test_a_caller_who_collects_less_or_never_keeps_it(callers: Thresholds) -> None:
    gc.set_threshold(*callers)
    seen: list[Thresholds] = []
    _run(_watched(_flight(), seen))
    assert set(seen) == {callers}
    assert gc.get_threshold() == callers
