"""The events' generated ``__init__`` (fuzzoff.events._fast_init) keeps the dataclass contract."""

from __future__ import annotations

import copy
import dataclasses
import inspect
import math
import pickle
from typing import Any

import pytest

from fuzzoff.events import (
    ALL_EVENT_TYPES,
    NOWHERE,
    Command,
    ControlMode,
    Event,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
    Where,
    event_from_dict,
    event_to_dict,
)
from fuzzoff.gate.transitions import GateTransition


@pytest.mark.parametrize("cls", ALL_EVENT_TYPES, ids=lambda c: c.__name__)
def test_defaults_and_keyword_only_fields_match_the_dataclass(cls: type[Event]) -> None:
    params = inspect.signature(cls.__init__).parameters
    fields = dataclasses.fields(cls)
    assert [name for name in params if name != "self"] == [f.name for f in fields]
    for f in fields:
        param = params[f.name]
        assert param.kind is inspect.Parameter.KEYWORD_ONLY
        expected = inspect.Parameter.empty if f.default is dataclasses.MISSING else f.default
        assert param.default is expected


def test_values_land_in_their_fields_and_the_event_stays_frozen() -> None:
    sp = SetPositionTargetLocal(
        t=1.5, vehicle="2", target_system=2, type_mask=7, position=(1.0, 2.0, -3.0)
    )
    assert (sp.t, sp.vehicle, sp.target_system, sp.type_mask) == (1.5, "2", 2, 7)
    assert sp.position == (1.0, 2.0, -3.0)
    assert sp.where is NOWHERE and sp.origin == "sent" and sp.transport == "mavlink"
    assert sp.coordinate_frame == 1 and sp.yaw == 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        sp.t = 2.0  # type: ignore[misc]
    status = VehicleStatus(t=0.0, nav_state=14)
    assert status.origin == "vehicle" and status.armed is None
    traj = TrajectorySetpoint(t=0.0)
    assert all(math.isnan(v) for v in traj.position)


def test_equality_hash_and_round_trip_are_the_dataclass_ones() -> None:
    a = ControlMode(t=1.0, where=Where("/fmu/in/offboard_control_mode", 3), position=True)
    b = ControlMode(t=1.0, where=Where("/fmu/in/offboard_control_mode", 3), position=True)
    assert a == b and hash(a) == hash(b)
    assert event_from_dict(event_to_dict(a)) == a
    assert a.flags() == ("position",) and a.first_flag() == "position"
    assert ControlMode(t=0.0).flags() == () and ControlMode(t=0.0).first_flag() is None


def test_missing_or_unknown_arguments_raise_type_error() -> None:
    with pytest.raises(TypeError, match="command"):
        Command(t=0.0)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        VehicleStatus(t=0.0, no_such_field=1)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        VehicleStatus(0.0)  # type: ignore[call-arg]


def test_where_keeps_its_positional_fields() -> None:
    where = Where("HEARTBEAT", 4, 120)
    assert (where.topic, where.index, where.offset) == ("HEARTBEAT", 4, 120)
    assert str(where) == "HEARTBEAT #4 @120"
    assert Where("x") == Where(topic="x", index=None, offset=None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        where.index = 5  # type: ignore[misc]


def _reference(cls: type[Event]) -> type:
    """The class as ``@dataclass(frozen=True, slots=True, kw_only=True)`` would make it."""
    spec = [(f.name, f.type, dataclasses.field(default=f.default)) for f in dataclasses.fields(cls)]
    ref = dataclasses.make_dataclass(cls.__name__, spec, frozen=True, slots=True, kw_only=True)
    ref.__qualname__ = cls.__qualname__
    return ref


@pytest.mark.parametrize("cls", [*ALL_EVENT_TYPES, GateTransition], ids=lambda c: c.__name__)
def test_repr_eq_hash_and_state_are_what_the_dataclass_gives(cls: type[Event]) -> None:
    """``events.event_type`` shares these methods between the classes instead of compiling
    them per class (issue 31): the same text, equality, hash, copy and pickle."""
    ref = _reference(cls)
    values: dict[str, Any] = {f.name: f.default for f in dataclasses.fields(cls)}
    values.update(t=2.5, vehicle="/px4_1", where=Where("x", 3, 40), sender_time_us=7)
    for f in dataclasses.fields(cls):
        if values[f.name] is dataclasses.MISSING:
            values[f.name] = f"{f.name}-value"
    event, twin = cls(**values), ref(**values)
    assert repr(event) == repr(twin)
    assert hash(event) == hash(twin)
    assert event.__getstate__() == twin.__getstate__()
    assert event == cls(**values) and event != cls(**{**values, "t": 3.0})
    assert event != twin and event.__eq__(twin) is NotImplemented
    assert copy.copy(event) == event
    assert repr(pickle.loads(pickle.dumps(event))) == repr(event)  # NaN != NaN once unpickled
    with pytest.raises(dataclasses.FrozenInstanceError):
        event.t = 1.0  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del event.t
    with pytest.raises(dataclasses.FrozenInstanceError):
        event.not_a_field = 1  # type: ignore[attr-defined]
    assert dataclasses.replace(event, t=4.0).t == 4.0
