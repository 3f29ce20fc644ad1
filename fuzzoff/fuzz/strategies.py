"""Hypothesis strategies, one per concept of a setpoint stream (composed in ``fuzz.streams``).

Timing: ``rates``, ``jitters``, ``stalls``, ``bursts``, ``held_streams``, ``held_commands``,
``keepalive_times``, ``clock_skews``.
Declarations: ``control_modes``. Content: ``nan_patterns``, ``trajectory_setpoints``,
``quaternions``, ``attitude_setpoints``, ``rates_setpoints``, ``rover_setpoints``,
``rover_programs``, ``frames``, ``type_masks``, ``mavlink_setpoints``. Commands:
``command_plans``. Parameters: ``gate_params``. Profile: ``px4_versions``, ``vehicle_types``.

Values are float32-representable (``width=32``): every recording format stores setpoints as
float32, so a stream survives the round trip through the writers unchanged.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, TypedDict

from hypothesis import strategies as st

from fuzzoff import releases
from fuzzoff.events import Quat, Vec3
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import VEHICLE_TYPES
from fuzzoff.releases import PX4Profile

NAN = math.nan
f32 = st.floats(min_value=-200.0, max_value=200.0, width=32, allow_nan=False)
"""A finite setpoint component (metres, m/s, rad)."""

# --------------------------------------------------------------------------- profile, params


def px4_versions(transport: str | None = None) -> st.SearchStrategy[PX4Profile]:
    """Modelled PX4 profiles; ROS 2 direct needs the boolean control mode of 1.13+."""
    if transport == "ros2":
        flags = [r.control_mode_flags for r in releases.RELEASES]
        return st.sampled_from([n for n, f in zip(releases.names(), flags, strict=True) if f])
    return st.sampled_from(releases.names())


def vehicle_types() -> st.SearchStrategy[str]:
    return st.sampled_from(VEHICLE_TYPES)


LOSS_TIMEOUTS = (0.2, 0.5, 1.0, 1.5, 2.0)


@st.composite
def gate_params(draw: st.DrawFn, px4: PX4Profile) -> dict[str, float]:
    """``COM_OF_LOSS_T``, the loss action (``COM_OBL_RC_ACT``) and whether an RC is present."""
    params: dict[str, float] = {}
    if draw(st.booleans()):
        params["COM_OF_LOSS_T"] = draw(
            st.one_of(
                st.sampled_from(LOSS_TIMEOUTS), st.floats(0.1, 3.0).map(lambda x: round(x, 2))
            )
        )
    if draw(st.booleans()):
        params["COM_OBL_RC_ACT"] = float(draw(st.integers(0, 7)))
    if draw(st.booleans()):
        params["FUZZOFF_RC_PRESENT"] = float(draw(st.integers(0, 1)))
    del px4  # every profile reads the same names (defaults differ, gate.md#params)
    return params


# --------------------------------------------------------------------------- timing


def rates() -> st.SearchStrategy[float]:
    """Keep-alive rate in Hz: around the documented 2 Hz and the usual 10-50 Hz."""
    return st.one_of(st.sampled_from([2.0, 5.0, 10.0, 20.0, 50.0]), st.floats(0.5, 60.0))


def jitters() -> st.SearchStrategy[float]:
    """Jitter as a fraction of the period (uniform +-)."""
    return st.one_of(st.just(0.0), st.floats(0.0, 0.9))


@dataclass(frozen=True, slots=True)
class Stall:
    """No message from ``at`` (seconds into the stream) for ``length`` seconds."""

    at: float
    length: float


def stalls(loss_timeout: float) -> st.SearchStrategy[list[Stall]]:
    """Gaps in the stream; lengths cluster around the loss timeout (the gate's threshold)."""
    near = st.floats(-0.15, 0.15).map(lambda d: max(0.0, round(loss_timeout + d, 3)))
    length = st.one_of(near, st.floats(0.0, 3.0))
    return st.lists(st.builds(Stall, at=st.floats(0.0, 6.0), length=length), max_size=2)


def bursts() -> st.SearchStrategy[list[tuple[float, int]]]:
    """(when, how many extra messages within 1 ms)."""
    return st.lists(st.tuples(st.floats(0.0, 6.0), st.integers(1, 5)), max_size=2)


@st.composite
def keepalive_times(draw: st.DrawFn, loss_timeout: float) -> list[float]:
    """Sorted send times of the keep-alive: a rate with jitter, stalls and bursts; now and
    then a long held stream (``held_streams``)."""
    held = draw(held_streams())
    if held is not None:
        duration, rate = held
    else:
        rate = draw(rates())
        # Hypothesis favours the ends of a range: typical durations get their own share.
        duration = draw(st.one_of(st.sampled_from([1.5, 2.5, 4.0, 6.0]), st.floats(0.0, 6.0)))
    period = 1.0 / rate
    jitter = draw(jitters())
    n = min(int(duration * rate) + 1, 400)
    offsets = draw(st.lists(st.floats(-1.0, 1.0), min_size=n, max_size=n)) if jitter else [0.0] * n
    times = [max(0.0, i * period + jitter * period * 0.5 * o) for i, o in enumerate(offsets)]
    for stall in draw(stalls(loss_timeout)):
        times = [t if t < stall.at else t + stall.length for t in times]
    for at, count in draw(bursts()):
        times += [at + 0.0002 * k for k in range(count)]
    return sorted(round(t, 4) for t in times)


HELD_SECONDS = (12.0, 15.0, 20.0)
"""Long enough that a command held unchanged reaches what only time shows (OFB107 asks for
10 s of one moving command)."""
HELD_RATES = (2.0, 5.0, 10.0, 20.0)
"""At most 20 Hz, so that 20 s stay within the ``keepalive_times`` cap of 400 messages."""


def held_streams() -> st.SearchStrategy[tuple[float, float] | None]:
    """Mostly None (an ordinary stream); else (duration s, rate Hz) of a long held stream."""
    return st.one_of(
        st.none(),
        st.none(),
        st.none(),
        st.tuples(st.sampled_from(HELD_SECONDS), st.sampled_from(HELD_RATES)),
    )


@dataclass(frozen=True, slots=True)
class HeldCommand:
    """One command that moves the vehicle, held identical in OFFBOARD for a long stream (what
    OFB107 waits 10 s for): how long, how often, how fast (m/s, or a rover's throttle)."""

    duration: float
    rate: float
    speed: float
    switch: float
    """When the switch to OFFBOARD is sent (after about 1 s of keep-alive, the arm before)."""


def held_commands() -> st.SearchStrategy[HeldCommand]:
    speed = st.floats(0.5, 5.0, width=32) | st.floats(-5.0, -0.5, width=32)
    return st.builds(
        HeldCommand,
        duration=st.sampled_from(HELD_SECONDS),
        rate=st.sampled_from(HELD_RATES),
        speed=speed,
        switch=st.sampled_from((1.0, 1.2, 1.5, 2.0)),
    )


@dataclass(frozen=True, slots=True)
class ClockSkew:
    """The sender's clock against the recording's: offset, drift, and swapped neighbours."""

    offset_s: float
    drift: float
    swaps: tuple[int, ...]

    def stamp(self, times: Sequence[float]) -> list[int]:
        stamps = [max(0, round((t + self.offset_s + t * self.drift) * 1e6)) for t in times]
        for i in self.swaps:
            if i + 1 < len(stamps):
                stamps[i], stamps[i + 1] = stamps[i + 1], stamps[i]
        return stamps


def clock_skews() -> st.SearchStrategy[ClockSkew]:
    """Mostly none; else an offset (negative = old timestamps), drift and reordering."""
    return st.one_of(
        st.just(ClockSkew(0.0, 0.0, ())),
        st.builds(
            ClockSkew,
            offset_s=st.one_of(st.floats(-3.0, 3.0), st.sampled_from([-1.0, 0.5, 5.0])),
            # -1 = a stopped clock; -0.5 = sim time at half speed; small = crystal drift
            drift=st.one_of(st.floats(-0.2, 0.2), st.sampled_from([-1.0, -0.5])),
            swaps=st.lists(st.integers(0, 40), max_size=3).map(tuple),
        ),
    )


# --------------------------------------------------------------------------- declarations

OCM_FLAGS_BEFORE_115 = ("position", "velocity", "acceleration", "attitude", "body_rate", "actuator")
OCM_FLAGS_115 = (
    "position",
    "velocity",
    "acceleration",
    "attitude",
    "body_rate",
    "thrust_and_torque",
    "direct_actuator",
)


class ControlModeFlags(TypedDict, total=False):
    """The ``ControlMode`` fields a generated ``OffboardControlMode`` sets."""

    position: bool
    velocity: bool
    acceleration: bool
    attitude: bool
    body_rate: bool
    thrust_and_torque: bool
    direct_actuator: bool
    actuator: bool
    layout: Literal["actuator", "thrust_and_torque"]


@st.composite
def control_modes(draw: st.DrawFn, px4: PX4Profile) -> ControlModeFlags:
    """``OffboardControlMode`` flags of the release's layout: usually one flag, sometimes a
    mix, sometimes none (OFB301)."""
    newer = releases.get(px4).control_mode == "thrust_and_torque"
    names = OCM_FLAGS_115 if newer else OCM_FLAGS_BEFORE_115
    layout: Literal["actuator", "thrust_and_torque"] = "thrust_and_torque" if newer else "actuator"
    chosen = draw(
        st.one_of(
            st.sampled_from(names).map(lambda n: {n}),
            st.sets(st.sampled_from(names), max_size=3),
        )
    )
    flags = ControlModeFlags(layout=layout)
    for name in chosen:
        flags[name] = True  # type: ignore[literal-required]  # a name of OCM_FLAGS_*
    return flags


# --------------------------------------------------------------------------- setpoint content


@dataclass(frozen=True, slots=True)
class NanPattern:
    """Which components are set (True) per vector: position, velocity, acceleration; yaw."""

    position: tuple[bool, bool, bool]
    velocity: tuple[bool, bool, bool]
    acceleration: tuple[bool, bool, bool]
    yaw: bool


_TRIPLE = st.tuples(st.booleans(), st.booleans(), st.booleans())
_COMMON_TRIPLES = st.sampled_from([(True, True, True), (False, False, False)])


_T, _F = True, False
TRICKY_PATTERNS = (
    NanPattern((_T, _F, _T), (_F, _T, _F), (_F, _F, _F), _T),  # x/y unpaired (gate.md#multicopter)
    NanPattern((_F, _F, _T), (_T, _T, _F), (_F, _F, _F), _T),  # altitude + horizontal velocity
    NanPattern((_T, _T, _F), (_F, _F, _F), (_F, _F, _F), _T),  # no vertical setpoint
    NanPattern((_F, _F, _F), (_F, _F, _F), (_T, _T, _T), _F),  # acceleration only
)
"""Patterns the docs' per-message description gets wrong (D13): decided per axis."""


def nan_patterns() -> st.SearchStrategy[NanPattern]:
    """Per-axis NaN patterns: the documented whole-vector ones, the tricky per-axis ones, and
    arbitrary per-axis mixes."""
    triple = st.one_of(_COMMON_TRIPLES, _TRIPLE)
    return st.one_of(
        st.builds(NanPattern, triple, triple, triple, st.booleans()),
        st.sampled_from(TRICKY_PATTERNS),
    )


def _vec(draw: st.DrawFn, mask: tuple[bool, bool, bool]) -> tuple[float, float, float]:
    x, y, z = (draw(f32) if m else NAN for m in mask)
    return (x, y, z)


class TrajectoryValues(TypedDict):
    position: Vec3
    velocity: Vec3
    acceleration: Vec3
    yaw: float


class AttitudeValues(TypedDict):
    q_d: Quat
    thrust_body: Vec3


class RatesValues(TypedDict):
    roll: float
    pitch: float
    yaw: float
    thrust_body: Vec3


RoverValues = dict[str, float | tuple[float, float]]
"""A rover setpoint's fields (each rover message has its own few)."""

SetpointValues = TrajectoryValues | AttitudeValues | RatesValues | RoverValues
"""The fields of one generated ROS 2 setpoint message, by message."""


@st.composite
def trajectory_values(draw: st.DrawFn, pattern: NanPattern) -> TrajectoryValues:
    """Field values of a ``TrajectorySetpoint`` following ``pattern``."""
    return {
        "position": _vec(draw, pattern.position),
        "velocity": _vec(draw, pattern.velocity),
        "acceleration": _vec(draw, pattern.acceleration),
        "yaw": draw(f32) if pattern.yaw else NAN,
    }


def trajectory_setpoints() -> st.SearchStrategy[TrajectoryValues]:
    return nan_patterns().flatmap(trajectory_values)


def _f32(x: float) -> float:
    import struct

    return float(struct.unpack("<f", struct.pack("<f", x))[0])


def quaternions() -> st.SearchStrategy[tuple[float, float, float, float]]:
    """Unit quaternions (w, x, y, z), and some that are not (zero, scaled, NaN)."""

    def unit(v: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
        n = math.sqrt(sum(c * c for c in v))
        if n < 1e-3:
            return (1.0, 0.0, 0.0, 0.0)
        w, x, y, z = (_f32(c / n) for c in v)
        return (w, x, y, z)

    comp = st.floats(-1.0, 1.0, width=32)
    raw = st.tuples(comp, comp, comp, comp)
    return st.one_of(
        raw.map(unit),
        raw,
        st.just((NAN, NAN, NAN, NAN)),
        st.just((0.0, 0.0, 0.0, 0.0)),
    )


def thrusts() -> st.SearchStrategy[float]:
    """Normalised thrust, sometimes out of [-1, 1] or NaN."""
    return st.one_of(st.floats(-1.0, 1.0, width=32), st.floats(-3.0, 3.0, width=32), st.just(NAN))


@st.composite
def attitude_setpoints(draw: st.DrawFn) -> AttitudeValues:
    return {"q_d": draw(quaternions()), "thrust_body": (0.0, 0.0, draw(thrusts()))}


@st.composite
def rates_setpoints(draw: st.DrawFn) -> RatesValues:
    rate = st.one_of(st.floats(-5.0, 5.0, width=32), st.just(NAN))
    return {
        "roll": draw(rate),
        "pitch": draw(rate),
        "yaw": draw(rate),
        "thrust_body": (0.0, 0.0, draw(thrusts())),
    }


ROVER_KINDS = (
    "rover_position",
    "rover_speed",
    "rover_attitude",
    "rover_rate",
    "rover_throttle",
    "rover_steering",
)


ROVER_COMBINATIONS: tuple[tuple[str, ...], ...] = (
    ("rover_speed", "rover_rate"),
    ("rover_speed", "rover_steering"),
    ("rover_speed", "rover_attitude"),
    ("rover_position",),
    ("rover_throttle", "rover_steering"),
)
"""The combinations the rover docs list (each needs the setpoints above it as NaN, OFB504)."""

ROVER_FLAG: dict[tuple[str, ...], str] = {
    ("rover_position",): "position",
    ("rover_speed", "rover_attitude"): "velocity",
    ("rover_speed", "rover_rate"): "velocity",
    ("rover_speed", "rover_steering"): "velocity",
    ("rover_throttle", "rover_attitude"): "attitude",
    ("rover_throttle", "rover_rate"): "body_rate",
    ("rover_throttle", "rover_steering"): "thrust_and_torque",
}
"""Every combination of the rover docs' table and the one ``OffboardControlMode`` flag it needs."""
ROVER_NAN: dict[tuple[str, ...], tuple[str, ...]] = {
    ("rover_speed", "rover_rate"): ("rover_attitude",),
    ("rover_speed", "rover_steering"): ("rover_attitude", "rover_rate"),
}
"""The setpoints a combination needs published as NaN (the docs' crosses)."""


@dataclass(frozen=True, slots=True)
class RoverProgram:
    """What a rover program publishes each cycle: the control-mode flag and its rover
    setpoints (kind, values), NaN ones included."""

    flag: str
    published: tuple[tuple[str, RoverValues], ...]


def _nan_values(values: RoverValues) -> RoverValues:
    return {k: (NAN, NAN) if isinstance(v, tuple) else NAN for k, v in values.items()}


@st.composite
def rover_programs(draw: st.DrawFn, available: Sequence[str] = ROVER_KINDS) -> RoverProgram:
    """A rover program as the docs describe it, mostly right: one of the table's combinations
    with values, its flag (now and then another: OFB503), and the crosses published as NaN,
    left out or given a value (OFB504)."""
    # the combinations with crosses twice: their NaN rule (OFB504) is the easiest to get wrong
    combos = [c for c in (*ROVER_FLAG, *ROVER_NAN) if all(k in available for k in c)]
    combo = draw(st.sampled_from(combos))
    right = ROVER_FLAG[combo]
    flag = draw(st.one_of(st.just(right), st.just(right), st.sampled_from(OCM_FLAGS_115)))
    published = [draw(rover_setpoints(kind, finite=True)) for kind in combo]
    for cross in ROVER_NAN.get(combo, ()):
        if cross not in available:
            continue
        policy = draw(st.sampled_from(("nan", "missing", "value")))
        if policy != "missing":
            kind, values = draw(rover_setpoints(cross, finite=True))
            published.append((kind, values if policy == "value" else _nan_values(values)))
    return RoverProgram(flag, tuple(published))


@st.composite
def rover_setpoints(
    draw: st.DrawFn, kind: str | None = None, finite: bool = False
) -> tuple[str, RoverValues]:
    """(kind, values) of one rover setpoint topic; NaN where the docs require it, or not
    (``finite``: every value a number, never 0 for the first: a setpoint that drives)."""
    kind = kind or draw(st.sampled_from(ROVER_KINDS))
    value: st.SearchStrategy[float] = (
        st.floats(0.25, 2.0, width=32) | st.floats(-2.0, -0.25, width=32)
        if finite
        else st.one_of(st.floats(-2.0, 2.0, width=32), st.just(NAN))
    )
    if kind == "rover_position":
        return kind, {"position_ned": (draw(f32), draw(f32)), "yaw": draw(value)}
    if kind == "rover_speed":
        return kind, {"speed_body_x": draw(value), "speed_body_y": draw(value)}
    if kind == "rover_attitude":
        return kind, {"yaw_setpoint": draw(value)}
    if kind == "rover_rate":
        return kind, {"yaw_rate_setpoint": draw(value)}
    if kind == "rover_throttle":
        return kind, {"throttle_body_x": draw(value), "throttle_body_y": draw(value)}
    return kind, {"normalized_steering_angle": draw(value), "normalized_speed_diff": draw(value)}


# --------------------------------------------------------------------------- MAVLink content

LOCAL_FRAMES = (1, 7, 8, 9, 20, 21)
GLOBAL_FRAMES = (5, 6, 11, 0, 3, 10)
COMMON_TYPE_MASKS = (
    0b110111111000,  # position
    0b110111000111,  # velocity
    0b110000111111,  # acceleration
    0b100111111000,  # position + yaw rate
    0b000111111000,  # position + yaw + yaw rate
    0b110000000000,  # position, velocity, acceleration
    0b0001000000000000 | 0b110111111000,  # fixed-wing takeoff bit
    3576,
    0,
)


def frames(kind: str) -> st.SearchStrategy[int]:
    """Coordinate frames: the supported ones, neighbours the receiver drops, and any value."""
    usual = LOCAL_FRAMES if kind == "local" else GLOBAL_FRAMES
    return st.one_of(st.sampled_from(usual), st.integers(0, 21))


def type_masks() -> st.SearchStrategy[int]:
    return st.one_of(st.sampled_from(COMMON_TYPE_MASKS), st.integers(0, 0xFFFF))


FW_TYPE_MASKS = (
    292,  # glide: z, vz and az ignored (PX4 flies it with the throttle off)
    0x1000 | 0b110111111000,  # takeoff
    0x2000 | 0b110111111000,  # land
    0x3000 | 0b110111111000,  # loiter
    0b110111111000,  # position (1.14-1.17 need x, y and z all given)
    0b110111000111,  # velocity (not flown in FW before 1.18)
)
"""What a fixed-wing program sends (PX4 answers each per release: gate spec section 16)."""


def vehicle_setpoints(vehicle: str | None) -> st.SearchStrategy[tuple[str, dict[str, Any]]]:
    """A MAVLink setpoint as a program for ``vehicle`` writes it: a fixed-wing's (or a VTOL's
    in FW) setpoint types and NaN altitude, a rover's ground-plane setpoint (z 0 or NaN), else
    any (``mavlink_setpoints``)."""
    if vehicle in ("fw", "vtol"):
        return mavlink_setpoints().flatmap(
            lambda sp: st.builds(
                _fw_shaped, st.just(sp), st.sampled_from(FW_TYPE_MASKS), st.booleans()
            )
        )
    if vehicle is not None and vehicle.startswith("rover"):
        return mavlink_setpoints().flatmap(
            lambda sp: st.builds(_ground_shaped, st.just(sp), st.sampled_from([0.0, NAN]))
        )
    return mavlink_setpoints()


def _fw_shaped(
    sp: tuple[str, dict[str, Any]], mask: int, nan_z: bool
) -> tuple[str, dict[str, Any]]:
    kind, fields = sp
    if kind == "set_attitude_target":
        return sp
    fields = {**fields, "type_mask": mask}
    if nan_z and "position" in fields:  # 1.18 glides on a NaN z (and vz)
        x, y, _ = fields["position"]
        vx, vy, _ = fields["velocity"]
        fields |= {"position": (x, y, NAN), "velocity": (vx, vy, NAN)}
    return kind, fields


def _ground_shaped(sp: tuple[str, dict[str, Any]], z: float) -> tuple[str, dict[str, Any]]:
    kind, fields = sp
    if "position" not in fields:
        return sp
    x, y, _ = fields["position"]
    vx, vy, _ = fields["velocity"]
    return kind, {**fields, "position": (x, y, z), "velocity": (vx, vy, 0.0)}


@st.composite
def mavlink_setpoints(draw: st.DrawFn) -> tuple[str, dict[str, Any]]:
    """(kind, fields) of one SET_POSITION_TARGET_* / SET_ATTITUDE_TARGET message."""
    kind = draw(st.sampled_from(("local", "local", "global", "attitude")))
    if kind == "attitude":
        mask = draw(st.one_of(st.sampled_from((0, 7, 0b10000111, 128, 64)), st.integers(0, 255)))
        return "set_attitude_target", {
            "type_mask": mask,
            "q": draw(quaternions()),
            "body_roll_rate": draw(st.floats(-3.0, 3.0, width=32)),
            "body_pitch_rate": draw(st.floats(-3.0, 3.0, width=32)),
            "body_yaw_rate": draw(st.floats(-3.0, 3.0, width=32)),
            "thrust": draw(thrusts()),
        }
    vec = st.tuples(f32, f32, f32)
    common = {
        "type_mask": draw(type_masks()),
        "velocity": draw(vec),
        "acceleration": draw(vec),
        "yaw": draw(st.floats(-3.0, 3.0, width=32)),
        "yaw_rate": draw(st.floats(-3.0, 3.0, width=32)),
    }
    if kind == "local":
        return "set_position_target_local_ned", {
            **common,
            "coordinate_frame": draw(frames("local")),
            "position": draw(vec),
        }
    return "set_position_target_global_int", {
        **common,
        "coordinate_frame": draw(frames("global")),
        "lat_int": draw(st.integers(-900_000_000, 900_000_000)),
        "lon_int": draw(st.integers(-1_800_000_000, 1_800_000_000)),
        "alt": draw(st.floats(-100.0, 500.0, width=32)),
    }


# --------------------------------------------------------------------------- commands


@dataclass(frozen=True, slots=True)
class CommandPlan:
    """When the stream's operator arms, switches to OFFBOARD, leaves it and disarms (None =
    never); ``set_nav_state`` uses ROS 2's VEHICLE_CMD_SET_NAV_STATE instead of DO_SET_MODE."""

    arm: float | None
    switch: float | None
    leave: float | None
    disarm: float | None
    set_nav_state: bool = False
    acks: bool = True


def _moment(duration: float) -> st.SearchStrategy[float | None]:
    return st.one_of(st.none(), st.floats(0.0, max(duration, 0.01)).map(lambda x: round(x, 3)))


@st.composite
def command_plans(draw: st.DrawFn, duration: float, ros2_nav_state: bool) -> CommandPlan:
    """Arm before or after the switch, the switch anywhere in the stream (often early, near
    the 1 s the docs ask for), maybe leave OFFBOARD and disarm later."""
    early = st.floats(0.0, 1.5).map(lambda x: round(x, 3))
    switch = draw(st.one_of(early, _moment(duration)))
    arm = draw(st.one_of(early, _moment(duration)))
    leave = draw(st.one_of(st.none(), _moment(duration + 1.0)))
    disarm = draw(st.one_of(st.none(), _moment(duration + 1.0)))
    return CommandPlan(
        arm=arm,
        switch=switch,
        leave=leave,
        disarm=disarm,
        set_nav_state=ros2_nav_state and draw(st.booleans()),
        acks=draw(st.booleans()),
    )


# --------------------------------------------------------------------------- helpers


def frozen_or_moving(values: Mapping[str, object]) -> Callable[[int], Mapping[str, object]]:
    """The i-th message's values: a frozen setpoint repeats them, a moving one shifts x."""

    def nth(i: int) -> Mapping[str, object]:
        pos = values.get("position")
        if isinstance(pos, tuple) and math.isfinite(pos[0]):
            return {**values, "position": (_f32(pos[0] + 0.01 * i), pos[1], pos[2])}
        return values

    return nth
