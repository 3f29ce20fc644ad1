"""The loss action is remembered by what it reads (``gate.failsafe.loss_action``): the memo's
key must name every parameter the action depends on, or a lint would report a stale action."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzzoff.gate import failsafe
from fuzzoff.gate.estimates import Estimates
from fuzzoff.profiles import VEHICLE_TYPES
from fuzzoff.releases import RELEASES, Release

VALUES = (0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, -1.0, 2.5)


class _Reads(dict[str, float]):
    """Parameters that note every name read from them."""

    def __init__(self, values: dict[str, float]) -> None:
        super().__init__(values)
        self.read: set[str] = set()

    def get(self, name: str, default: float | None = None) -> float | None:  # type: ignore[override]
        self.read.add(name)
        return super().get(name, default)

    def __getitem__(self, name: str) -> float:
        self.read.add(name)
        return super().__getitem__(name)


def _estimates(bits: int, rc_recorded: bool) -> Estimates:
    return Estimates(
        local_position=bool(bits & 1),
        local_velocity=bool(bits & 2),
        local_altitude=bool(bits & 4),
        global_position=bool(bits & 8),
        attitude=bool(bits & 16),
        angular_velocity=bool(bits & 32),
        home_position=bool(bits & 64),
        rc_present=bool(bits & 128),
        rc_recorded=rc_recorded,
    )


@pytest.mark.parametrize("release", RELEASES, ids=lambda r: r.name)
def test_every_parameter_the_loss_action_reads_is_in_the_memo_key(release: Release) -> None:
    read: set[str] = set()
    for vehicle, stage, bits, rc_recorded, value in itertools.product(
        VEHICLE_TYPES, (1, 2), (0, 7, 15, 127, 255), (False, True), VALUES
    ):
        params = _Reads({name: value for name in failsafe.READ_PARAMS})
        failsafe._loss_action(release, vehicle, params, _estimates(bits, rc_recorded), stage)
        read |= params.read
    assert read <= set(failsafe.READ_PARAMS)


@given(
    release=st.sampled_from(RELEASES),
    vehicle=st.sampled_from(VEHICLE_TYPES),
    stage=st.sampled_from((1, 2)),
    bits=st.integers(0, 255),
    rc_recorded=st.booleans(),
    params=st.dictionaries(st.sampled_from(failsafe.READ_PARAMS), st.sampled_from(VALUES)),
)
def test_a_remembered_loss_action_is_the_one_worked_out_afresh(
    release: Release,
    vehicle: str,
    stage: int,
    bits: int,
    rc_recorded: bool,
    params: dict[str, float],
) -> None:
    est = _estimates(bits, rc_recorded)
    first = failsafe.loss_action(release, vehicle, params, est, stage)
    again = failsafe.loss_action(release, vehicle, dict(params), est, stage)
    fresh = failsafe._loss_action(release, vehicle, params, est, stage)
    assert first == fresh and again == fresh
