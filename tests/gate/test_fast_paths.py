"""The gate's per-message caches give what the uncached computation gives.

A snapshot (what the checks read while they judge a run of stream messages at once) keeps the
prediction the run saw while the live model moves on.

``receiver.shape`` keys ``receive``'s verdict; the model keeps accepted verdicts per shape and
drops them when a parameter or an estimate changes; stamped keep-alives keep the cached deadline
only while the loss does not move earlier.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from fuzzoff import releases
from fuzzoff.events import (
    ControlMode,
    Event,
    FailsafeFlags,
    MavlinkTarget,
    Parameter,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
)
from fuzzoff.gate import GateModel
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.receiver import FLOAT_FIELDS, ReceiverContext, receive, shape
from fuzzoff.profiles import Profile
from tests.gate.streams import ALL, POSCTL, in_offboard, local_ned, of, run, status

FLOATS = st.sampled_from([0.0, -0.0, 1.5, -2.0, 1e308, -1e308, math.nan, math.inf, -math.inf])
VEC = st.tuples(FLOATS, FLOATS, FLOATS)
MASKS = st.sampled_from([0, 0x9F8, 0xDF8, 0xDC7, 0x1C7, 0x3F, 0x238, 0x1000, 0x2000, 0xFFF, 0x5FF])
IDS = st.sampled_from([0, 1, 2])


@st.composite
def messages(draw: st.DrawFn) -> MavlinkTarget:
    kind = draw(st.sampled_from(["local", "global", "attitude"]))
    common: dict[str, Any] = {
        "t": 0.0,
        "type_mask": draw(MASKS),
        "target_system": draw(IDS),
        "target_component": draw(IDS),
    }
    if kind == "attitude":
        return SetAttitudeTarget(
            q=(draw(FLOATS), draw(FLOATS), draw(FLOATS), draw(FLOATS)),
            body_roll_rate=draw(FLOATS),
            body_pitch_rate=draw(FLOATS),
            body_yaw_rate=draw(FLOATS),
            thrust=draw(FLOATS),
            **common,
        )
    vectors = {"velocity": draw(VEC), "acceleration": draw(VEC)}
    yaw = {"yaw": draw(FLOATS), "yaw_rate": draw(FLOATS)}
    if kind == "global":
        frame = draw(st.sampled_from([5, 6, 11, 1]))
        return SetPositionTargetGlobal(
            coordinate_frame=frame, alt=draw(FLOATS), **vectors, **yaw, **common
        )
    frame = draw(st.sampled_from([1, 8, 9]))
    return SetPositionTargetLocal(
        coordinate_frame=frame, position=draw(VEC), **vectors, **yaw, **common
    )


def _context(px4: str, fwdextsp: bool, component: int, est: Estimates) -> ReceiverContext:
    return ReceiverContext(
        release=releases.get(px4),
        own_system=1,
        own_component=component,
        fwdextsp=fwdextsp,
        est=est,
    )


def _finite_twin(msg: MavlinkTarget, value: float) -> MavlinkTarget:
    """The same message with every float replaced by ``value`` (finite)."""
    if isinstance(msg, SetAttitudeTarget):
        return SetAttitudeTarget(
            t=msg.t,
            type_mask=msg.type_mask,
            target_system=msg.target_system,
            target_component=msg.target_component,
            q=(value,) * 4,
            body_roll_rate=value,
            body_pitch_rate=value,
            body_yaw_rate=value,
            thrust=value,
        )
    fields: dict[str, Any] = {
        "t": msg.t,
        "type_mask": msg.type_mask,
        "target_system": msg.target_system,
        "target_component": msg.target_component,
        "velocity": (value,) * 3,
        "acceleration": (value,) * 3,
        "yaw": value,
        "yaw_rate": value,
    }
    if isinstance(msg, SetPositionTargetGlobal):
        return SetPositionTargetGlobal(coordinate_frame=msg.coordinate_frame, alt=value, **fields)
    assert isinstance(msg, SetPositionTargetLocal)
    return SetPositionTargetLocal(
        coordinate_frame=msg.coordinate_frame, position=(value,) * 3, **fields
    )


@settings(max_examples=400, deadline=None)
@given(
    messages(),
    st.sampled_from(ALL),
    st.booleans(),
    st.sampled_from([0, 1]),
    st.booleans(),
    st.sampled_from([0.25, -3.0, 7.0]),
)
def test_messages_of_one_shape_get_one_verdict(
    msg: MavlinkTarget, px4: str, fwdextsp: bool, component: int, glob: bool, value: float
) -> None:
    est = Estimates(global_position=glob, home_position=glob)
    ctx = _context(px4, fwdextsp, component, est)
    key = shape(msg)
    values = [getattr(msg, name, 0.0) for name in ("yaw", "yaw_rate", "alt", "thrust")]
    if key is None:
        return  # not cached: receive() itself answers
    assert all(math.isfinite(v) for v in values if isinstance(v, float))
    twin = _finite_twin(msg, value)
    assert shape(twin) == key
    assert receive(twin, ctx) == receive(msg, ctx)


def test_a_non_finite_field_is_never_cached() -> None:
    for bad in (math.nan, math.inf, -math.inf):
        assert shape(local_ned(0.0, position=(0.0, bad, 0.0))) is None
        assert shape(local_ned(0.0, velocity=(0.0, 0.0, bad))) is None
        assert shape(local_ned(0.0, yaw_rate=bad)) is None
        assert shape(SetAttitudeTarget(t=0.0, q=(1.0, 0.0, bad, 0.0))) is None
        assert shape(SetPositionTargetGlobal(t=0.0, alt=bad)) is None
    # an overflowing sum only takes the uncached path
    assert shape(local_ned(0.0, position=(1e308, 1e308, 0.0))) is None


def test_the_shape_settles_every_float_field_the_receiver_reads() -> None:
    """Each field of ``FLOAT_FIELDS`` made NaN takes the message off the cached path: the
    unrolled shape functions and the table (which the checks use) name the same fields."""
    for cls, (vectors, values) in FLOAT_FIELDS.items():
        base = cls(t=0.0)
        assert shape(base) is not None, cls
        for name in vectors:
            width = len(getattr(base, name))
            for i in range(width):
                vector = tuple(math.nan if j == i else 0.0 for j in range(width))
                assert shape(replace(base, **{name: vector})) is None, (cls, name, i)
        for name in values:
            assert shape(replace(base, **{name: math.nan})) is None, (cls, name)


def _dropped(trs: list[Any]) -> list[str]:
    return [tr.reason for tr in of("setpoint_dropped", trs)]


def test_a_parameter_change_drops_the_cached_verdicts() -> None:
    events: list[Event] = [in_offboard()]
    events += [local_ned(i * 0.05, position=(0.0, 0.0, -1.0)) for i in range(10)]
    events.append(Parameter(t=0.52, name="MAV_FWDEXTSP", value=0.0))
    events += [local_ned(0.55 + i * 0.05, position=(0.0, 0.0, -1.0)) for i in range(4)]
    trs = run("1.15", events, t_end=3.0)
    assert _dropped(trs) == ["MAV_FWDEXTSP is 0: setpoint handling is off"]
    assert of("signal_lost", trs)


def test_an_estimate_change_drops_the_cached_verdicts() -> None:
    def global_int(t: float) -> SetPositionTargetGlobal:
        return SetPositionTargetGlobal(
            t=t, type_mask=0xDF8, coordinate_frame=6, target_system=1, target_component=1
        )

    events: list[Event] = [in_offboard()]
    events += [global_int(i * 0.05) for i in range(10)]
    events.append(FailsafeFlags(t=0.52, global_position_valid=False))
    events += [global_int(0.55 + i * 0.05) for i in range(4)]
    trs = run("1.15", events)
    assert _dropped(trs) == ["no global position reference (dropped silently)"]


def test_stamped_keepalives_that_lag_still_lose_the_signal() -> None:
    """A sender clock that stops: each keep-alive arrives with the same stamp, so the loss
    comes COM_OF_LOSS_T after that stamp, not after the newest arrival."""
    gate = GateModel(Profile(px4="main"), {}, "1")
    events: list[Event] = [in_offboard()]
    for i in range(40):
        t = round(i * 0.05, 6)
        stamp_us = min(i, 10) * 50_000  # stops at 0.5 s
        events.append(ControlMode(t=t, position=True, sender_time_us=stamp_us))
    trs = run("main", events, model=gate)
    lost = of("signal_lost", trs)
    assert lost and math.isclose(lost[0].t_earliest or 0.0, 1.5, abs_tol=1e-9)


def test_a_stamp_that_jumps_back_moves_the_loss_earlier() -> None:
    """The newest keep-alive's stamp is 0.5 s older than the one before: the loss follows the
    stamp (1.5 s), not the deadline cached for the one before (2.0 s)."""
    events: list[Event] = [in_offboard()]
    for i in range(21):
        t = round(i * 0.05, 6)
        stamp_us = 500_000 if i == 20 else round(t * 1e6)
        events.append(ControlMode(t=t, position=True, sender_time_us=stamp_us))
    events.append(in_offboard(1.7))  # a later event: the loss must come before it
    trs = run("main", events, t_end=3.0)
    lost = of("signal_lost", trs)
    assert lost and math.isclose(lost[0].t_earliest or 0.0, 1.5, abs_tol=1e-9)


def test_a_snapshot_keeps_the_prediction_its_run_saw() -> None:
    gate = GateModel(Profile(px4="1.15"), {}, "1")
    for event in (in_offboard(), ControlMode(t=0.0, position=True)):
        gate.feed(event)
    snap = gate.snapshot()
    assert snap.in_offboard and snap.armed is True and snap.offboard_since == 0.0
    gate.feed(status(0.5, POSCTL, False, POSCTL))  # a pilot's switch and a disarm
    gate.feed(Parameter(t=0.6, name="COM_OF_LOSS_T", value=2.0))
    assert not gate.in_offboard and gate.armed is False and gate.offboard_since is None
    assert snap.in_offboard and snap.armed is True and snap.nav_state == 14
    assert snap.params is gate.params and snap.params["COM_OF_LOSS_T"] == 2.0
    assert snap.loss_timeout == 1.0 and gate.loss_timeout == 2.0
