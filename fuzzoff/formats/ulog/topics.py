"""uORB topics in a ULog -> normalised events, one decoder per topic (formats.md 2.2, 8.1).

A topic whose event is plain copies of its columns is one line of ``DECODERS`` (``copied``:
event field -> column); a decoder of its own is written only where a release spells a field
otherwise, a value is computed from several columns, or the context is needed.

A decoder sees a ``Chunk``: a slice of a topic's numpy columns (as pyulog returns them) turned
into Python lists, and yields events. Field layouts differ between releases; decoders go by
field names, so one decoder reads every release's layout (``ignore_*`` and boolean control
modes, ``x, y, z`` and ``position[3]`` trajectories, ...). Every event has origin "vehicle":
a ULog is PX4's own copy of what it received or computed.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterable, Iterator, Mapping
from itertools import repeat
from typing import Any, Literal

import numpy as np

from fuzzoff import events as ev
from fuzzoff.formats.uorb import ESTIMATES
from fuzzoff.formats.uorb import TOPICS as UORB_TOPICS
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name

VEHICLE: Literal["vehicle"] = "vehicle"

Columns = Mapping[str, Any]
"""Field name -> numpy array (one topic instance, as in ``ULog.Data.data``)."""


@dataclass(slots=True)
class Context:
    """What decoders need beyond their own topic."""

    legacy_arming: bool = False
    """Legacy ``arming_state`` numbering: ARMED 2 and ARMED_ERROR 3 are both armed (gate 11)."""
    intention_ts: Any = None
    """``commander_state`` timestamps (sorted numpy array) for the <= v1.13 user intention."""
    intention_nav: list[int | None] | None = None


class Chunk:
    """Rows ``sel`` of one topic instance, as Python values, with the common event header."""

    def __init__(self, cols: Columns, sel: Any, topic: str, t0: int) -> None:
        self.cols = cols
        self.sel = sel
        ts = cols["timestamp"][sel]
        self.ts: list[int] = ts.tolist()
        with np.errstate(all="ignore"):
            seconds = np.maximum((ts.astype(np.float64) - t0) / 1e6, 0.0)
        self.t: list[float] = seconds.tolist()
        index = np.arange(len(cols["timestamp"]))[sel].tolist()
        self.index: list[int] = index
        # Made as the decoder's zip reads them (one pass): each Where is then only referenced
        # by its event, which the consumer drops at once; a list of a chunk's Wheres kept
        # thousands of objects alive for the garbage collector to walk over and over.
        self.where: Iterator[ev.Where] = map(ev.Where, repeat(topic), index)
        self.n = len(self.ts)

    def has(self, name: str) -> bool:
        return name in self.cols

    def f(self, name: str) -> list[float]:
        """Float column; NaN where the layout has no such field."""
        if name not in self.cols:
            return [math.nan] * self.n
        with np.errstate(all="ignore"):  # a damaged log may hold any bit pattern
            values: list[float] = self.cols[name][self.sel].astype(np.float64).tolist()
        return values

    def i(self, name: str, default: int = 0) -> list[int]:
        if name not in self.cols:
            return [default] * self.n
        values: list[int] = self.cols[name][self.sel].tolist()
        return values

    def b(self, name: str) -> list[bool]:
        if name not in self.cols:
            return [False] * self.n
        values: list[bool] = (self.cols[name][self.sel] != 0).tolist()
        return values

    def ob(self, name: str) -> list[bool | None]:
        """Optional bool: None where the layout has no such field."""
        if name not in self.cols:
            return [None] * self.n
        return list(self.b(name))

    def vec(self, name: str, size: int) -> Iterator[Any]:
        """Array field ``name[0..size)`` as tuples (typed loosely: the size varies by field),
        made as the decoder's ``zip`` reads them (one pass), like ``where``."""
        return zip(*(self.f(f"{name}[{k}]") for k in range(size)), strict=True)

    def matching(self, prefix: str, suffix: str) -> list[str]:
        """The fields named ``prefix...suffix``, in layout order."""
        if isinstance(self.cols, _Watched):
            self.cols.patterns.add((prefix, suffix))
        return [name for name in self.cols if name.startswith(prefix) and name.endswith(suffix)]

    def width(self, name: str) -> int:
        """The length of array field ``name`` in this layout."""
        size = 0
        while f"{name}[{size}]" in self.cols:
            size += 1
        return size


Decoder = Callable[[Chunk, Context], Iterable[ev.Event]]
"""A chunk's events, one per row, in row order (a generator, or a list for the hot topics)."""


def _legacy_thrust(c: Chunk) -> Iterable[Any]:
    """Legacy scalar ``thrust`` (0..1, up) as a body thrust vector (FRD: negative z)."""
    if c.has("thrust_body[0]"):
        return c.vec("thrust_body", 3)
    return [(0.0, 0.0, -v) if not math.isnan(v) else ev.NAN3 for v in c.f("thrust")]


def control_mode(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    if c.has("ignore_thrust"):
        if c.has("ignore_bodyrate"):
            bodyrate = c.b("ignore_bodyrate")
        else:  # v1.7-v1.11 split it per axis; the rates are used if any axis is
            x, y, z = c.b("ignore_bodyrate_x"), c.b("ignore_bodyrate_y"), c.b("ignore_bodyrate_z")
            bodyrate = [a and b and d for a, b, d in zip(x, y, z, strict=True)]
        for t, w, ts, *row in zip(
            c.t,
            c.where,
            c.ts,
            c.b("ignore_thrust"),
            c.b("ignore_attitude"),
            bodyrate,
            c.b("ignore_position"),
            c.b("ignore_velocity"),
            c.b("ignore_acceleration_force"),
            c.b("ignore_alt_hold"),
            strict=True,
        ):
            yield ev.LegacyControlMode(
                t=t,
                where=w,
                sender_time_us=ts,
                origin=VEHICLE,
                ignore_thrust=row[0],
                ignore_attitude=row[1],
                ignore_bodyrate=row[2],
                ignore_position=row[3],
                ignore_velocity=row[4],
                ignore_acceleration_force=row[5],
                ignore_alt_hold=row[6],
            )
        return
    new = c.has("thrust_and_torque")
    layout: Literal["actuator", "thrust_and_torque"] = "thrust_and_torque" if new else "actuator"
    for t, w, ts, pos, vel, acc, att, rate, tt, direct, act in zip(
        c.t,
        c.where,
        c.ts,
        c.b("position"),
        c.b("velocity"),
        c.b("acceleration"),
        c.b("attitude"),
        c.b("body_rate"),
        c.b("thrust_and_torque"),
        c.b("direct_actuator"),
        c.b("actuator"),
        strict=True,
    ):
        yield ev.ControlMode(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            position=pos,
            velocity=vel,
            acceleration=acc,
            attitude=att,
            body_rate=rate,
            thrust_and_torque=tt,
            direct_actuator=direct,
            actuator=act,
            layout=layout,
        )


def trajectory(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    position: Iterable[Any]
    velocity: Iterable[Any]
    if c.has("position[0]"):
        position, velocity = c.vec("position", 3), c.vec("velocity", 3)
    else:  # v1.13 layout
        position = list(zip(c.f("x"), c.f("y"), c.f("z"), strict=True))
        velocity = list(zip(c.f("vx"), c.f("vy"), c.f("vz"), strict=True))
    for t, w, ts, pos, vel, acc, jerk, yaw, yawspeed in zip(
        c.t,
        c.where,
        c.ts,
        position,
        velocity,
        c.vec("acceleration", 3),
        c.vec("jerk", 3),
        c.f("yaw"),
        c.f("yawspeed"),
        strict=True,
    ):
        yield ev.TrajectorySetpoint(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            position=pos,
            velocity=vel,
            acceleration=acc,
            jerk=jerk,
            yaw=yaw,
            yawspeed=yawspeed,
        )


def attitude(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    for t, w, ts, q, thrust, move in zip(
        c.t, c.where, c.ts, c.vec("q_d", 4), _legacy_thrust(c), c.f("yaw_sp_move_rate"), strict=True
    ):
        yield ev.AttitudeSetpoint(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            q_d=q,
            thrust_body=thrust,
            yaw_sp_move_rate=move,
        )


def rates(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    for t, w, ts, roll, pitch, yaw, thrust in zip(
        c.t, c.where, c.ts, c.f("roll"), c.f("pitch"), c.f("yaw"), _legacy_thrust(c), strict=True
    ):
        yield ev.RatesSetpoint(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            roll=roll,
            pitch=pitch,
            yaw=yaw,
            thrust_body=thrust,
        )


Column = Callable[[Chunk], Iterable[Any]]
"""One event field's values for a chunk's rows, read from the topic's columns."""


def floats(name: str) -> Column:
    return lambda c: c.f(name)


def ints(name: str) -> Column:
    return lambda c: c.i(name)


def bools(name: str) -> Column:
    return lambda c: c.b(name)


def vector(name: str, size: int) -> Column:
    """``name[0..size)`` as tuples."""
    return lambda c: c.vec(name, size)


def array(name: str) -> Column:
    """``name[...]`` as tuples as long as the layout's array."""
    return lambda c: c.vec(name, c.width(name))


def copied(cls: type[ev.Event], **fields: Column) -> Decoder:
    """The decoder of a topic whose event is plain copies of its columns: event field ->
    where its values come from. A topic whose fields need more (another release's
    spelling, values computed from several columns, the context) has a decoder of its own."""
    names = tuple(fields)
    columns = tuple(fields.values())

    def decode(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
        rows = zip(*(column(c) for column in columns), strict=True)
        fields = map(dict, map(zip, repeat(names), rows))  # each row's fields, made in C
        for t, w, ts, row in zip(c.t, c.where, c.ts, fields, strict=True):
            yield cls(t=t, where=w, sender_time_us=ts, origin=VEHICLE, **row)

    return decode


def steering(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    name = (
        "normalized_steering_setpoint"  # v1.17+
        if c.has("normalized_steering_setpoint")
        else "normalized_steering_angle"
    )
    for t, w, ts, angle, diff in zip(
        c.t, c.where, c.ts, c.f(name), c.f("normalized_speed_diff"), strict=True
    ):
        yield ev.RoverSteeringSetpoint(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            normalized_steering_angle=angle,
            normalized_speed_diff=diff,
        )


def _vehicle_types(c: Chunk) -> list[int | None]:
    if c.has("vehicle_type"):
        return list(c.i("vehicle_type"))
    if c.has("is_rotary_wing"):  # legacy: no vehicle_type; rovers report MAV_TYPE 10
        system = c.i("system_type")
        return [
            1 if rotary else 3 if mav == 10 else 2
            for rotary, mav in zip(c.b("is_rotary_wing"), system, strict=True)
        ]
    return [None] * c.n


def _intentions(c: Chunk, ctx: Context) -> list[int | None]:
    if c.has("nav_state_user_intention"):
        return list(c.i("nav_state_user_intention"))
    if ctx.intention_ts is None or ctx.intention_nav is None:
        return [None] * c.n
    ts = c.cols["timestamp"][c.sel]
    at = np.searchsorted(ctx.intention_ts, ts, side="right") - 1
    nav = ctx.intention_nav
    return [nav[k] if k >= 0 else None for k in at.tolist()]


def vehicle_status(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    arming = c.i("arming_state")
    armed = [a in (2, 3) if ctx.legacy_arming else a == 2 for a in arming]
    for t, w, ts, nav, arm, intention, failsafe, vtype, vtol, transition in zip(
        c.t,
        c.where,
        c.ts,
        c.i("nav_state"),
        armed,
        _intentions(c, ctx),
        c.ob("failsafe"),
        _vehicle_types(c),
        c.ob("is_vtol"),
        c.ob("in_transition_mode"),
        strict=True,
    ):
        yield ev.VehicleStatus(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            nav_state=nav,
            mode=nav_state_name(nav),
            armed=arm,
            user_intention=intention,
            failsafe=failsafe,
            vehicle_type=vtype,
            is_vtol=vtol,
            vtol_phase=ev.vtol_phase_of(vtype, transition) if vtol else None,
        )


_FLAG_PREFIX, _FLAG_SUFFIX = "flag_control_", "_enabled"


def control_mode_status(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    names = c.matching(_FLAG_PREFIX, _FLAG_SUFFIX)
    short = [name[len(_FLAG_PREFIX) : -len(_FLAG_SUFFIX)] for name in names]
    columns = [c.b(name) for name in names]
    for t, w, ts, offboard, *flags in zip(
        c.t, c.where, c.ts, c.b("flag_control_offboard_enabled"), *columns, strict=True
    ):
        enabled = frozenset(s for s, on in zip(short, flags, strict=True) if on)
        yield ev.VehicleControlModeStatus(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            offboard_enabled=offboard,
            enabled=enabled,
        )


def _valid(c: Chunk, estimate: str) -> list[bool | None]:
    """``*_valid`` from whichever spelling the release logs (``*_invalid`` from v1.14)."""
    if c.has(f"{estimate}_invalid"):
        return [not v for v in c.b(f"{estimate}_invalid")]
    for name in (f"condition_{estimate}_valid", f"{estimate}_valid"):
        if c.has(name):
            return list(c.b(name))
    return [None] * c.n


def local_position(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    """``vehicle_local_position``; a coordinate PX4 marks invalid (``xy_valid``, ``z_valid``)
    is NaN: the estimator's value then means nothing."""
    nan = math.nan
    xy_ok = c.b("xy_valid") if c.has("xy_valid") else repeat(True)
    z_ok = c.b("z_valid") if c.has("z_valid") else repeat(True)
    for t, w, ts, x, y, z, xy, zv in zip(
        c.t, c.where, c.ts, c.f("x"), c.f("y"), c.f("z"), xy_ok, z_ok, strict=False
    ):
        if not xy:
            x = y = nan
        yield ev.VehiclePosition(t=t, where=w, sender_time_us=ts, x=x, y=y, z=z if zv else nan)


def failsafe_flags(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    manual = (
        "manual_control_signal_lost" if c.has("manual_control_signal_lost") else "rc_signal_lost"
    )
    valid = [_valid(c, name) for name in ESTIMATES]
    for t, w, ts, lost, manual_lost, *flags in zip(
        c.t, c.where, c.ts, c.ob("offboard_control_signal_lost"), c.ob(manual), *valid, strict=True
    ):
        yield ev.FailsafeFlags(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            offboard_control_signal_lost=lost,
            manual_control_signal_lost=manual_lost,
            **{f"{name}_valid": v for name, v in zip(ESTIMATES, flags, strict=True)},
        )


def land_detected(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    """``vehicle_land_detected``: Commander refuses a disarm unless ``landed`` or
    ``maybe_landed`` (gate.md#seen-on-px4)."""
    for t, w, ts, landed, maybe in zip(
        c.t, c.where, c.ts, c.ob("landed"), c.ob("maybe_landed"), strict=True
    ):
        value = None if landed is None else bool(landed or maybe)
        yield ev.LandDetected(t=t, where=w, sender_time_us=ts, origin=VEHICLE, landed=value)


def manual_control(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    """``manual_control_setpoint``: the sticks PX4 flies by (1.14+ names; throttle in [-1, 1])
    and ManualControl's ``sticks_moving`` verdict where logged (gate spec 16 S1)."""
    for t, w, ts, roll, pitch, yaw, throttle, moving in zip(
        c.t,
        c.where,
        c.ts,
        c.f("roll"),
        c.f("pitch"),
        c.f("yaw"),
        c.f("throttle"),
        c.ob("sticks_moving"),
        strict=True,
    ):
        yield ev.ManualControl(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            roll=roll,
            pitch=pitch,
            yaw=yaw,
            throttle=throttle,
            sticks_moving=moving,
        )


def command(c: Chunk, ctx: Context) -> Iterator[ev.Event]:
    params = list(zip(*(c.f(f"param{k}") for k in range(1, 8)), strict=True))
    for t, w, ts, p, cmd, tsys, tcomp, ssys, scomp, external in zip(
        c.t,
        c.where,
        c.ts,
        params,
        c.i("command"),
        c.i("target_system"),
        c.i("target_component"),
        c.i("source_system"),
        c.i("source_component"),
        c.ob("from_external"),
        strict=True,
    ):
        yield ev.Command(
            t=t,
            where=w,
            sender_time_us=ts,
            origin=VEHICLE,
            command=cmd,
            params=p,
            target_system=tsys,
            target_component=tcomp,
            source_system=ssys,
            source_component=scomp,
            from_external=external,
            transport="uorb",
        )


@dataclass(frozen=True, slots=True)
class TopicSpec:
    kind: str
    decode: Decoder
    default_interval_s: float | None = None
    """PX4's default logger interval for this topic (formats.md 8.1), where it is known."""
    setpoint: bool = False
    """An offboard keep-alive or setpoint topic: subsampled by the logger."""


DECODERS: dict[str, Decoder] = {
    "vehicle_command": command,
    "offboard_control_mode": control_mode,
    "trajectory_setpoint": trajectory,
    "vehicle_attitude_setpoint": attitude,
    "vehicle_rates_setpoint": rates,
    "vehicle_thrust_setpoint": copied(ev.ThrustSetpoint, xyz=vector("xyz", 3)),
    "vehicle_torque_setpoint": copied(ev.TorqueSetpoint, xyz=vector("xyz", 3)),
    "actuator_motors": copied(
        ev.ActuatorMotors, control=array("control"), reversible_flags=ints("reversible_flags")
    ),
    "actuator_servos": copied(ev.ActuatorServos, control=array("control")),
    "rover_position_setpoint": copied(
        ev.RoverPositionSetpoint,
        position_ned=vector("position_ned", 2),
        start_ned=vector("start_ned", 2),
        cruising_speed=floats("cruising_speed"),
        arrival_speed=floats("arrival_speed"),
        yaw=floats("yaw"),
    ),
    "rover_speed_setpoint": copied(
        ev.RoverSpeedSetpoint,
        speed_body_x=floats("speed_body_x"),
        speed_body_y=floats("speed_body_y"),
    ),
    "rover_attitude_setpoint": copied(
        ev.RoverAttitudeSetpoint, yaw_setpoint=floats("yaw_setpoint")
    ),
    "rover_rate_setpoint": copied(
        ev.RoverRateSetpoint, yaw_rate_setpoint=floats("yaw_rate_setpoint")
    ),
    "rover_throttle_setpoint": copied(
        ev.RoverThrottleSetpoint,
        throttle_body_x=floats("throttle_body_x"),
        throttle_body_y=floats("throttle_body_y"),
    ),
    "rover_steering_setpoint": steering,
    "position_setpoint_triplet": copied(
        ev.PositionSetpointTriplet,
        previous_valid=bools("previous.valid"),
        current_valid=bools("current.valid"),
        next_valid=bools("next.valid"),
        current_type=ints("current.type"),
        current_position_valid=bools("current.position_valid"),
        current_velocity_valid=bools("current.velocity_valid"),
        current_yaw_valid=bools("current.yaw_valid"),
    ),
    "vehicle_command_ack": copied(
        ev.CommandAck,
        command=ints("command"),
        result=ints("result"),
        target_system=ints("target_system"),
        target_component=ints("target_component"),
    ),
    "vehicle_status": vehicle_status,
    "vehicle_control_mode": control_mode_status,
    "failsafe_flags": failsafe_flags,
    "vehicle_status_flags": failsafe_flags,
    "vehicle_land_detected": land_detected,
    "vehicle_local_position": local_position,
    "manual_control_setpoint": manual_control,
}
"""uORB topic -> its decoder (what each topic is: ``uorb.TOPICS``)."""

TOPICS: dict[str, TopicSpec] = {
    name: TopicSpec(
        UORB_TOPICS[name].kind,
        decode,
        UORB_TOPICS[name].log_interval_s,
        UORB_TOPICS[name].setpoint,
    )
    for name, decode in DECODERS.items()
}
"""uORB topic -> what it becomes. Dict order = the order of events at the same microsecond."""

EXTRA_FIELDS: dict[str, tuple[str, ...]] = {"commander_state": ("timestamp", "main_state")}
"""Topics loaded but not turned into events of their own (merged into ``vehicle_status``),
with the fields read from them."""
EXTRA_TOPICS = tuple(EXTRA_FIELDS)


GPS_TOPICS = ("vehicle_gps_position",)
"""Loaded for the plots too: the first fix with a UTC time dates the log (a ULog's own clock
is the time since boot)."""


class _Watched(Mapping[str, Any]):
    """A topic's columns that note every field name a decoder asks for."""

    def __init__(self, cols: Columns) -> None:
        self.cols = cols
        self.asked: set[str] = set()
        self.patterns: set[tuple[str, str]] = set()
        """(prefix, suffix) of the fields read by pattern (``Chunk.matching``)."""

    def __contains__(self, name: object) -> bool:
        if isinstance(name, str):
            self.asked.add(name)
        return name in self.cols

    def __getitem__(self, name: str) -> Any:
        self.asked.add(name)
        return self.cols[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self.cols)

    def __len__(self) -> int:
        return len(self.cols)


def renamed_fields(
    cols: Columns, decode: Decoder | None, read: Iterable[str] = ()
) -> list[tuple[str, str]]:
    """(wanted, found) pairs: a field ``decode`` (or the caller: ``read``) reads that this layout
    lacks, beside a field not read whose name is as long and one character apart. No release
    names its fields so; a byte flipped in the topic's format record does, and the field would
    then read as absent (NaN, False) without a sign. The decoder is run on no rows to learn the
    names it reads."""
    watched = _Watched(cols)
    watched.asked.update(read)
    if decode is not None:
        with contextlib.suppress(Exception):  # a decoder that needs a row: the names so far
            for _ in decode(Chunk(watched, slice(0, 0), "", 0), Context()):
                pass
    present = {name.split("[", 1)[0] for name in cols}
    asked = {name.split("[", 1)[0] for name in watched.asked}
    unread = sorted(present - asked)
    pairs = [
        (wanted, found)
        for wanted in sorted(asked - present)
        for found in unread
        if len(wanted) == len(found) and _apart(wanted, found) == 1
    ]
    for prefix, suffix in sorted(watched.patterns):
        pairs += [
            (f"{prefix}...{suffix}", found)
            for found in unread
            if len(found) > len(prefix) + len(suffix)
            and _apart(prefix, found[: len(prefix)]) + _apart(suffix, found[-len(suffix) :]) == 1
        ]
    return pairs


def _apart(a: str, b: str) -> int:
    """How many characters two names of one length differ in."""
    return sum(x != y for x, y in zip(a, b, strict=True))
