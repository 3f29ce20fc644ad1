"""The normalised event stream: one small frozen dataclass per thing a recording can say.

Every reader (tlog, ULog, MCAP, ROS 2 bag, ROS 1 bag) turns its library's messages into these
events, in recording-time order. The gate model and the checks see only these, never a
library object. Field names follow px4_msgs / MAVLink where one exists; units are SI (metres,
radians, seconds), frames as the message defines them (NED/FRD for PX4, MAVROS is converted to
what MAVROS sends PX4 before it becomes an event).

Common header of every event:

* ``t``: recording time in seconds from the recording's first message (any topic);
* ``vehicle``: which vehicle it belongs to, as text: the MAVLink system id (``"1"``) or the ROS
  namespace (``""`` for none, ``"/px4_1"``);
* ``where``: topic or MAVLink message type, and index / byte offset in the file where known;
* ``sender_time_us``: the sender's own clock where the message carries one (PX4 ``timestamp``,
  MAVLink ``time_boot_ms`` x 1000), else ``None``;
* ``origin``: ``"sent"`` for a message on its way to the vehicle as recorded on the wire or the
  bus (ROS 2 ``/fmu/in``, MAVLink to the autopilot), ``"vehicle"`` for what the vehicle itself
  reports or logged internally (ULog topics, ``/fmu/out``, HEARTBEAT, MAVROS state), ``"model"``
  for what fuzzoff's gate model predicts (``fuzzoff.gate.GateTransition``).
"""

from __future__ import annotations

import math
import types
from collections.abc import Callable
from dataclasses import MISSING, FrozenInstanceError, dataclass, fields
from itertools import compress
from operator import attrgetter
from typing import TYPE_CHECKING, Any, ClassVar, Literal, TypeVar, dataclass_transform

# Named through ``events`` by the gate, the reports and the fuzz streams, beside Command.
from fuzzoff.mavlink_ids import MAV_CMD_COMPONENT_ARM_DISARM as MAV_CMD_COMPONENT_ARM_DISARM
from fuzzoff.mavlink_ids import MAV_CMD_DO_SET_MODE as MAV_CMD_DO_SET_MODE

Origin = Literal["sent", "vehicle", "model"]
Transport = Literal["ros2", "mavlink", "mavros", "uorb"]
CommandMessage = Literal["COMMAND_LONG", "COMMAND_INT", "SET_MODE"]
"""The MAVLink message a ``Command`` came in (PX4 checks their addresses differently)."""

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

NAN = math.nan
NAN3: Vec3 = (NAN, NAN, NAN)


def whole(value: float) -> int | None:
    """``int(value)`` (toward zero, as PX4's casts), or None for NaN and the infinities, which a
    recording may hold where PX4 reads a whole number (C leaves their cast undefined)."""
    return int(value) if math.isfinite(value) else None


def nearest(value: float) -> int | None:
    """``round(value)``, or None for NaN and the infinities."""
    return round(value) if math.isfinite(value) else None


def _fast_init(cls: type, *, kw_only: bool) -> None:
    """Replace a frozen slots dataclass's ``__init__`` by one that stores through the slots.

    A frozen dataclass's generated ``__init__`` stores every field with
    ``object.__setattr__(self, name, value)`` (a name lookup on the type per field); calling
    each slot's member descriptor directly does the same store without that lookup. Measured
    on Python 3.11: a ``SetPositionTargetLocal`` (17 fields) builds in 0.95 µs instead of
    1.8 µs, a ``Where`` in 0.3 µs instead of 0.5 µs; readers build one or two per message. The
    class stays frozen (assignment still raises); signature, defaults and errors are the
    dataclass's own (same keyword-only/positional layout, same default objects).
    """
    params = []
    body = []
    namespace: dict[str, Any] = {}
    for f in fields(cls):
        descriptor = getattr(cls, f.name)
        assert isinstance(descriptor, types.MemberDescriptorType), (cls, f.name)
        namespace[f"_set_{f.name}"] = descriptor.__set__
        if f.default is not MISSING:
            namespace[f"_default_{f.name}"] = f.default
            params.append(f"{f.name}=_default_{f.name}")
        else:
            assert f.default_factory is MISSING, (cls, f.name)
            params.append(f.name)
        body.append(f"    _set_{f.name}(self, {f.name})\n")
    star = "*, " if kw_only else ""
    source = f"def __init__(self, {star}{', '.join(params)}) -> None:\n{''.join(body)}"
    exec(source, namespace)  # generated from the dataclass fields above, nothing else
    init = namespace["__init__"]
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    cls.__init__ = init  # type: ignore[misc]


@dataclass(frozen=True, slots=True)
class Where:
    """Where an event sits in its file: topic or message type, and index / byte offset."""

    topic: str
    index: int | None = None
    offset: int | None = None

    def __str__(self) -> str:
        parts = [self.topic]
        if self.index is not None:
            parts.append(f"#{self.index}")
        if self.offset is not None:
            parts.append(f"@{self.offset}")
        return " ".join(parts)


_fast_init(Where, kw_only=False)

NOWHERE = Where("")

_E = TypeVar("_E", bound=type)


@dataclass_transform(kw_only_default=True, frozen_default=True)
def event_type(cls: _E) -> _E:
    """``@dataclass(frozen=True, slots=True, kw_only=True)`` for an ``Event`` class, at a fifth
    of its import cost (issue 31: the 43 event classes were a fifth of a ULog lint's start-up,
    six functions compiled for each). ``dataclass`` keeps the fields and the slots; the
    methods it would compile per class (``__repr__``, ``__eq__``, ``__hash__``, the frozen
    ``__setattr__`` and ``__delattr__``, the state for copy and pickle) are ``Event``'s, the
    same for every class, over the fields' values in order as the dataclass ones (read by
    one ``attrgetter``); ``__init__`` is compiled once, by ``_fast_init``, instead of twice.
    ``tests/test_event_init.py`` holds the result to the dataclass contract.
    """
    made: Any = dataclass(slots=True, kw_only=True, init=False, repr=False, eq=False)
    made = made(cls)
    names = tuple(f.name for f in fields(made))
    made._field_names = names
    made._field_values = attrgetter(*names)  # a tuple: every event has the five header fields
    _fast_init(made, kw_only=True)
    result: _E = made
    return result


@event_type
class Event:
    """Common header; never instantiated directly."""

    kind: ClassVar[str] = "event"
    _field_names: ClassVar[tuple[str, ...]]
    _field_values: ClassVar[Callable[[Any], tuple[Any, ...]]]
    """The fields' values in order (the tuple the dataclass ``__eq__`` and ``__hash__`` use)."""

    t: float
    vehicle: str = ""
    where: Where = NOWHERE
    sender_time_us: int | None = None
    origin: Origin = "sent"

    def __repr__(self) -> str:
        values = type(self)._field_values(self)
        body = ", ".join(f"{n}={v!r}" for n, v in zip(self._field_names, values, strict=True))
        return f"{type(self).__qualname__}({body})"

    def __eq__(self, other: object) -> bool:
        if other.__class__ is self.__class__:
            values = type(self)._field_values
            return bool(values(self) == values(other))
        return NotImplemented

    def __hash__(self) -> int:
        return hash(type(self)._field_values(self))

    if not TYPE_CHECKING:  # mypy knows the class is frozen (``event_type``)

        def __setattr__(self, name: str, value: object) -> None:
            raise FrozenInstanceError(f"cannot assign to field {name!r}")

        def __delattr__(self, name: str) -> None:
            raise FrozenInstanceError(f"cannot delete field {name!r}")

    def __getstate__(self) -> list[Any]:
        """The frozen slots dataclass's state (copy, pickle): the fields' values in order."""
        return list(type(self)._field_values(self))

    def __setstate__(self, state: list[Any]) -> None:
        for name, value in zip(type(self)._field_names, state, strict=True):
            object.__setattr__(self, name, value)


# ---------------------------------------------------------------------------------------------
# Keep-alive / control-mode declarations (ROS 2 OffboardControlMode, uORB offboard_control_mode)


@event_type
class ControlMode(Event):
    """``OffboardControlMode`` (1.13+ boolean layout). Field order is PX4's priority order.

    ``actuator`` is the single flag of 1.13/1.14; ``thrust_and_torque`` and ``direct_actuator``
    replace it from 1.15. ``layout`` says which one the message had.
    """

    kind: ClassVar[str] = "control_mode"

    position: bool = False
    velocity: bool = False
    acceleration: bool = False
    attitude: bool = False
    body_rate: bool = False
    thrust_and_torque: bool = False
    direct_actuator: bool = False
    actuator: bool = False
    layout: Literal["actuator", "thrust_and_torque"] = "thrust_and_torque"

    FLAG_ORDER: ClassVar[tuple[str, ...]] = (
        "position",
        "velocity",
        "acceleration",
        "attitude",
        "body_rate",
        "thrust_and_torque",
        "direct_actuator",
        "actuator",
    )

    def flags(self) -> tuple[str, ...]:
        """The true flags, in priority order."""
        # one attrgetter call and compress() instead of a getattr per flag (0.43 µs instead of
        # 0.64 µs): the control-mode rules ask for every OffboardControlMode
        return tuple(compress(self.FLAG_ORDER, _FLAG_VALUES(self)))

    def first_flag(self) -> str | None:
        """The first true flag: the one that selects the controller chain (None if empty)."""
        for name in self.FLAG_ORDER:  # usually the first one or two: getattr beats attrgetter
            if getattr(self, name):
                return name
        return None


_FLAG_VALUES = attrgetter(*ControlMode.FLAG_ORDER)
"""The flags of an ``OffboardControlMode`` as a tuple, in ``FLAG_ORDER``."""


@event_type
class LegacyControlMode(Event):
    """Legacy (v1.5-v1.11) ``offboard_control_mode`` with ``ignore_*`` flags (seed 003)."""

    kind: ClassVar[str] = "legacy_control_mode"

    ignore_thrust: bool = False
    ignore_attitude: bool = False
    ignore_bodyrate: bool = False
    ignore_position: bool = False
    ignore_velocity: bool = False
    ignore_acceleration_force: bool = False
    ignore_alt_hold: bool = False


# ---------------------------------------------------------------------------------------------
# PX4 setpoint topics (ROS 2 /fmu/in/..., or their uORB copies in a ULog)


@event_type
class TrajectorySetpoint(Event):
    """``TrajectorySetpoint``; the 1.13 ``x, y, z, vx...`` layout is normalised. NaN = unset."""

    kind: ClassVar[str] = "trajectory"

    position: Vec3 = NAN3
    velocity: Vec3 = NAN3
    acceleration: Vec3 = NAN3
    jerk: Vec3 = NAN3
    yaw: float = NAN
    yawspeed: float = NAN


@event_type
class AttitudeSetpoint(Event):
    """``VehicleAttitudeSetpoint``: ``q_d`` (w, x, y, z) and normalised ``thrust_body``."""

    kind: ClassVar[str] = "attitude"

    q_d: Quat = (NAN, NAN, NAN, NAN)
    thrust_body: Vec3 = NAN3
    yaw_sp_move_rate: float = NAN


@event_type
class RatesSetpoint(Event):
    """``VehicleRatesSetpoint``: body rates (rad/s) and normalised ``thrust_body``."""

    kind: ClassVar[str] = "rates"

    roll: float = NAN
    pitch: float = NAN
    yaw: float = NAN
    thrust_body: Vec3 = NAN3


@event_type
class ThrustSetpoint(Event):
    """``VehicleThrustSetpoint``: normalised FRD thrust."""

    kind: ClassVar[str] = "thrust"

    xyz: Vec3 = NAN3


@event_type
class TorqueSetpoint(Event):
    """``VehicleTorqueSetpoint``: normalised FRD torque."""

    kind: ClassVar[str] = "torque"

    xyz: Vec3 = NAN3


@event_type
class ActuatorMotors(Event):
    """``ActuatorMotors``: normalised motor commands; NaN = that motor is off (disarmed)."""

    kind: ClassVar[str] = "actuator_motors"

    control: tuple[float, ...] = ()
    reversible_flags: int = 0


@event_type
class ActuatorServos(Event):
    """``ActuatorServos``: normalised servo commands."""

    kind: ClassVar[str] = "actuator_servos"

    control: tuple[float, ...] = ()


@event_type
class RoverPositionSetpoint(Event):
    """``RoverPositionSetpoint``: NED target and start, cruising and arrival speed, yaw."""

    kind: ClassVar[str] = "rover_position"

    position_ned: Vec2 = (NAN, NAN)
    start_ned: Vec2 = (NAN, NAN)
    cruising_speed: float = NAN
    arrival_speed: float = NAN
    yaw: float = NAN


@event_type
class RoverSpeedSetpoint(Event):
    """``RoverSpeedSetpoint``: body-frame speeds (m/s)."""

    kind: ClassVar[str] = "rover_speed"

    speed_body_x: float = NAN
    speed_body_y: float = NAN


@event_type
class RoverAttitudeSetpoint(Event):
    """``RoverAttitudeSetpoint``: yaw (rad)."""

    kind: ClassVar[str] = "rover_attitude"

    yaw_setpoint: float = NAN


@event_type
class RoverRateSetpoint(Event):
    """``RoverRateSetpoint``: yaw rate (rad/s)."""

    kind: ClassVar[str] = "rover_rate"

    yaw_rate_setpoint: float = NAN


@event_type
class RoverThrottleSetpoint(Event):
    """``RoverThrottleSetpoint``: normalised body-frame throttle."""

    kind: ClassVar[str] = "rover_throttle"

    throttle_body_x: float = NAN
    throttle_body_y: float = NAN


@event_type
class RoverSteeringSetpoint(Event):
    """``RoverSteeringSetpoint``: 1.16 ``normalized_steering_angle`` / ``normalized_speed_diff``,
    1.17+ ``normalized_steering_setpoint`` (stored in ``normalized_steering_angle``)."""

    kind: ClassVar[str] = "rover_steering"

    normalized_steering_angle: float = NAN
    normalized_speed_diff: float = NAN


@event_type
class PositionSetpointTriplet(Event):
    """Legacy ``position_setpoint_triplet`` (only what the legacy rules need)."""

    kind: ClassVar[str] = "position_setpoint_triplet"

    previous_valid: bool = False
    current_valid: bool = False
    next_valid: bool = False
    current_type: int = 0
    current_position_valid: bool = False
    current_velocity_valid: bool = False
    current_yaw_valid: bool = False


# ---------------------------------------------------------------------------------------------
# MAVLink setpoints (from a tlog, or what MAVROS sends for a ROS setpoint topic)


@event_type
class MavlinkTarget(Event):
    """Fields every MAVLink setpoint carries: addressing, sender and the raw ``type_mask``."""

    kind: ClassVar[str] = "mavlink_target"

    target_system: int = 0
    target_component: int = 0
    source_system: int | None = None
    source_component: int | None = None
    type_mask: int = 0
    transport: Transport = "mavlink"


@event_type
class SetPositionTargetLocal(MavlinkTarget):
    """``SET_POSITION_TARGET_LOCAL_NED`` (#84), values as sent (NED or body frame)."""

    kind: ClassVar[str] = "set_position_target_local_ned"

    coordinate_frame: int = 1
    position: Vec3 = (0.0, 0.0, 0.0)
    velocity: Vec3 = (0.0, 0.0, 0.0)
    acceleration: Vec3 = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    yaw_rate: float = 0.0


@event_type
class SetPositionTargetGlobal(MavlinkTarget):
    """``SET_POSITION_TARGET_GLOBAL_INT`` (#86): ``lat_int``/``lon_int`` in 1e-7 degrees."""

    kind: ClassVar[str] = "set_position_target_global_int"

    coordinate_frame: int = 5
    lat_int: int = 0
    lon_int: int = 0
    alt: float = 0.0
    velocity: Vec3 = (0.0, 0.0, 0.0)
    acceleration: Vec3 = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    yaw_rate: float = 0.0


@event_type
class SetAttitudeTarget(MavlinkTarget):
    """``SET_ATTITUDE_TARGET`` (#82): quaternion (w, x, y, z), body rates, thrust."""

    kind: ClassVar[str] = "set_attitude_target"

    q: Quat = (1.0, 0.0, 0.0, 0.0)
    body_roll_rate: float = 0.0
    body_pitch_rate: float = 0.0
    body_yaw_rate: float = 0.0
    thrust: float = 0.0
    thrust_body: Vec3 | None = None


MAVLINK_SETPOINTS: tuple[type[MavlinkTarget], ...] = (
    SetPositionTargetLocal,
    SetPositionTargetGlobal,
    SetAttitudeTarget,
)


@event_type
class SetActuatorControlTarget(Event):
    """``SET_ACTUATOR_CONTROL_TARGET`` (#139): eight normalised controls of one actuator
    control group (MAVSDK's ``set_actuator_control``, MAVROS ``actuator_control``). Not a
    keep-alive: the docs list the three setpoints above, and PX4 1.14+ has no handler for it."""

    kind: ClassVar[str] = "set_actuator_control_target"

    group_mlx: int = 0
    controls: tuple[float, ...] = (0.0,) * 8
    target_system: int = 0
    target_component: int = 0
    source_system: int | None = None
    source_component: int | None = None


PX4_SETPOINTS: tuple[type[Event], ...] = (
    TrajectorySetpoint,
    AttitudeSetpoint,
    RatesSetpoint,
    ThrustSetpoint,
    TorqueSetpoint,
    ActuatorMotors,
    ActuatorServos,
    RoverPositionSetpoint,
    RoverSpeedSetpoint,
    RoverAttitudeSetpoint,
    RoverRateSetpoint,
    RoverThrottleSetpoint,
    RoverSteeringSetpoint,
)


# ---------------------------------------------------------------------------------------------
# Vehicle state as the vehicle reports it

NAV_STATE_OFFBOARD = 14


VtolPhase = Literal["mc", "fw", "transition"]
"""A VTOL flies as a multicopter, as a fixed-wing, or is between the two: PX4's ``vehicle_status``
``vehicle_type`` with ``in_transition_mode``, MAVLink ``EXTENDED_SYS_STATE.vtol_state``."""


def vtol_phase_of(vehicle_type: int | None, in_transition: bool | None) -> VtolPhase | None:
    """The phase from PX4's ``vehicle_status`` of a VTOL (``vehicle_type`` 1 rotary, 2 fixed)."""
    if in_transition:
        return "transition"
    if vehicle_type == 1:
        return "mc"
    return "fw" if vehicle_type == 2 else None


MAV_VTOL_STATE_PHASE: dict[int, VtolPhase] = {1: "transition", 2: "transition", 3: "mc", 4: "fw"}
"""``EXTENDED_SYS_STATE.vtol_state`` (0 undefined: not a VTOL) -> the phase."""


@event_type
class VehicleStatus(Event):
    """Mode and arming as reported (``vehicle_status``, HEARTBEAT, ``/mavros/state``).

    ``nav_state`` uses PX4's ``vehicle_status.nav_state`` numbering whatever the source
    (HEARTBEAT custom modes and MAVROS mode strings are mapped); ``mode`` is its name.
    ``user_intention`` is ``nav_state_user_intention`` (v1.14+) or the v1.13 main state
    mapped to a nav state, where recorded.
    """

    kind: ClassVar[str] = "vehicle_status"

    nav_state: int | None = None
    mode: str = ""
    armed: bool | None = None
    user_intention: int | None = None
    failsafe: bool | None = None
    vehicle_type: int | None = None
    is_vtol: bool | None = None
    vtol_phase: VtolPhase | None = None
    """A VTOL's phase at this moment (None: not a VTOL, or not recorded)."""
    origin: Origin = "vehicle"

    @property
    def in_offboard(self) -> bool:
        return self.nav_state == NAV_STATE_OFFBOARD


@event_type
class VehicleControlModeStatus(Event):
    """``vehicle_control_mode``: which controllers PX4 has enabled (``flag_control_*``)."""

    kind: ClassVar[str] = "vehicle_control_mode"

    offboard_enabled: bool = False
    enabled: frozenset[str] = frozenset()
    origin: Origin = "vehicle"


@event_type
class FailsafeFlags(Event):
    """Estimate and link validity (``failsafe_flags`` v1.14+, ``vehicle_status_flags`` before).

    ``None`` = not recorded. ``*_valid`` are the negations of PX4's ``*_invalid`` flags.
    """

    kind: ClassVar[str] = "failsafe_flags"

    offboard_control_signal_lost: bool | None = None
    manual_control_signal_lost: bool | None = None
    local_position_valid: bool | None = None
    local_velocity_valid: bool | None = None
    local_altitude_valid: bool | None = None
    global_position_valid: bool | None = None
    attitude_valid: bool | None = None
    angular_velocity_valid: bool | None = None
    home_position_valid: bool | None = None
    origin: Origin = "vehicle"


ESTIMATES: tuple[str, ...] = (
    "local_position",
    "local_velocity",
    "local_altitude",
    "global_position",
    "attitude",
    "angular_velocity",
    "home_position",
)
"""The estimates ``FailsafeFlags`` carries, each as ``<name>_valid`` (PX4's ``<name>_invalid``
negated), in PX4's order."""


@event_type
class ManualControl(Event):
    """The sticks as PX4 reads them (MAVLink ``MANUAL_CONTROL`` sent to the vehicle, uORB
    ``manual_control_setpoint``): ``roll``, ``pitch``, ``yaw`` and ``throttle`` in [-1, 1]
    (throttle centred at 0, as PX4 keeps it); ``sticks_moving`` is PX4's own verdict where the
    recording logs it (a ULog), None where it does not (gate spec 16 S1)."""

    kind: ClassVar[str] = "manual_control"

    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    throttle: float = 0.0
    sticks_moving: bool | None = None


@event_type
class LandDetected(Event):
    """The land detector's verdict, which PX4 reads when it judges a disarm request
    (gate.md#seen-on-px4:
    refused in flight). ``landed`` is what Commander tests, ``landed or maybe_landed``
    (ULog ``vehicle_land_detected``), or MAVLink ``EXTENDED_SYS_STATE.landed_state`` ON_GROUND
    (IN_AIR, TAKEOFF and LANDING are not landed; UNDEFINED is ``None``)."""

    kind: ClassVar[str] = "land_detected"

    landed: bool | None = None
    origin: Origin = "vehicle"


# ---------------------------------------------------------------------------------------------
# Commands, acks, parameters, vehicle identity

VEHICLE_CMD_SET_NAV_STATE = 100001
PX4_MAIN_MODE_OFFBOARD = 6


@event_type
class Command(Event):
    """A command: ``COMMAND_LONG``/``COMMAND_INT``/``SET_MODE`` or ``VehicleCommand``.

    ``SET_MODE`` (#11, what MAVROS ``set_mode`` sends) is normalised to ``DO_SET_MODE`` with
    ``param1`` = base mode and ``param2`` = custom main mode, as PX4 itself does.
    """

    kind: ClassVar[str] = "command"

    command: int
    params: tuple[float, float, float, float, float, float, float] = (0.0,) * 7
    target_system: int = 0
    target_component: int = 0
    source_system: int | None = None
    source_component: int | None = None
    from_external: bool | None = None
    transport: Transport = "mavlink"
    message: CommandMessage | None = None
    """The MAVLink message as recorded (None: not MAVLink, or not said)."""

    @property
    def is_offboard_switch(self) -> bool:
        """A switch to OFFBOARD (DO_SET_MODE custom main mode 6, or SET_NAV_STATE 14)."""
        if self.command == MAV_CMD_DO_SET_MODE:
            base = whole(self.params[0])
            main = whole(self.params[1])
            return base is not None and base & 1 == 1 and main == PX4_MAIN_MODE_OFFBOARD
        if self.command == VEHICLE_CMD_SET_NAV_STATE:
            return whole(self.params[0]) == NAV_STATE_OFFBOARD
        return False

    @property
    def is_mode_switch(self) -> bool:
        return self.command in (MAV_CMD_DO_SET_MODE, VEHICLE_CMD_SET_NAV_STATE)

    @property
    def is_arm(self) -> bool:
        return self.command == MAV_CMD_COMPONENT_ARM_DISARM and nearest(self.params[0]) == 1

    @property
    def is_disarm(self) -> bool:
        return self.command == MAV_CMD_COMPONENT_ARM_DISARM and nearest(self.params[0]) == 0


ACK_RESULT_NAMES = {
    0: "ACCEPTED",
    1: "TEMPORARILY_REJECTED",
    2: "DENIED",
    3: "UNSUPPORTED",
    4: "FAILED",
    5: "IN_PROGRESS",
    6: "CANCELLED",
}


@event_type
class CommandAck(Event):
    """``COMMAND_ACK`` / ``VehicleCommandAck``. 1.16/1.17 ack a mode switch twice: last wins."""

    kind: ClassVar[str] = "command_ack"

    command: int
    result: int
    target_system: int = 0
    target_component: int = 0
    origin: Origin = "vehicle"

    @property
    def accepted(self) -> bool:
        return self.result == 0

    @property
    def result_name(self) -> str:
        return ACK_RESULT_NAMES.get(self.result, str(self.result))


@event_type
class Parameter(Event):
    """A parameter value the recording shows (``PARAM_VALUE``, ULog parameters)."""

    kind: ClassVar[str] = "parameter"

    name: str
    value: float
    origin: Origin = "vehicle"


@event_type
class VehicleInfo(Event):
    """What the recording says about the vehicle's identity (firmware, airframe).

    ``px4_version``: the release as ``"1.15.4"`` where known; ``vehicle_type``: one of the
    profile names (``mc``, ``fw``, ``vtol``, ``rover-ackermann``...) where it can be told;
    ``mav_type``: MAVLink ``MAV_TYPE`` where known.
    """

    kind: ClassVar[str] = "vehicle_info"

    px4_version: str | None = None
    vehicle_type: str | None = None
    mav_type: int | None = None
    origin: Origin = "vehicle"


@event_type
class StatusText(Event):
    """A human-readable message from the vehicle (STATUSTEXT, ULog logged message). Untrusted."""

    kind: ClassVar[str] = "status_text"

    severity: int = 6
    text: str = ""
    origin: Origin = "vehicle"


@event_type
class VehiclePosition(Event):
    """Where the vehicle estimates it is, local NED in metres (ULog and ROS 2
    ``vehicle_local_position``, MAVLink ``LOCAL_POSITION_NED``, MAVROS ``local_position/pose``
    turned back into NED); NaN where PX4 marks the coordinate invalid. OFB404 compares vertical
    setpoints with its ``z``; a plain lint reads one per ``recording.POSITION_PERIOD_S``, the
    HTML report's plots every one."""

    kind: ClassVar[str] = "vehicle_position"

    x: float = NAN
    y: float = NAN
    z: float = NAN
    origin: Origin = "vehicle"


@event_type
class Dropout(Event):
    """The logger itself lost data here (ULog dropout record) for ``duration_s``."""

    kind: ClassVar[str] = "dropout"

    duration_s: float = 0.0
    origin: Origin = "vehicle"


# ---------------------------------------------------------------------------------------------
# External modes (px4-ros2-interface-lib and PX4's ModeManagement, PX4 1.15+): registration,
# the arming-check exchange that keeps a registration alive, unregistration, and on 1.18 the
# setpoint types an external mode asks for. Ids are as the messages carry them (-1: none).


@event_type
class ExtComponentRequest(Event):
    """``RegisterExtComponentRequest``: a companion asks PX4 to register an arming check, a
    mode and / or a mode executor under ``name``; ``api_version`` is the request's
    ``px4_ros2_api_version`` (the library's own ``LATEST_PX4_ROS2_API_VERSION``)."""

    kind: ClassVar[str] = "ext_component_request"

    request_id: int = 0
    name: str = ""
    api_version: int = 0
    arming_check: bool = False
    mode: bool = False
    executor: bool = False


@event_type
class ExtComponentReply(Event):
    """``RegisterExtComponentReply``: PX4's answer; ``api_version`` is PX4's own
    ``LATEST_PX4_ROS2_API_VERSION`` (1 up to 1.17, 2 on 1.18 and main), whatever the request
    said."""

    kind: ClassVar[str] = "ext_component_reply"

    request_id: int = 0
    name: str = ""
    api_version: int = 0
    success: bool = False
    arming_check_id: int = -1
    mode_id: int = -1
    executor_id: int = -1
    origin: Origin = "vehicle"


@event_type
class ArmingCheckRequest(Event):
    """``ArmingCheckRequest``: PX4 asks every registered component for its checks (every
    300 ms). ``registrations_mask`` (1.17+: ``valid_registrations_mask``) has a bit per
    registration PX4 still counts as valid and responsive; None where the release lacks it."""

    kind: ClassVar[str] = "arming_check_request"

    request_id: int = 0
    registrations_mask: int | None = None
    origin: Origin = "vehicle"


@event_type
class ArmingCheckReply(Event):
    """``ArmingCheckReply``: one registered component's answer to request ``request_id``."""

    kind: ClassVar[str] = "arming_check_reply"

    request_id: int = 0
    registration_id: int = 0
    can_arm_and_run: bool = True


@event_type
class ExtComponentUnregister(Event):
    """``UnregisterExtComponent``: the companion removes what it registered (ids from the
    reply, -1 for none)."""

    kind: ClassVar[str] = "ext_component_unregister"

    name: str = ""
    arming_check_id: int = -1
    mode_id: int = -1
    executor_id: int = -1


@event_type
class SetpointConfig(Event):
    """``SetpointConfig`` (1.18+): an external mode says which setpoint type it will send."""

    kind: ClassVar[str] = "setpoint_config"

    setpoint_type: int = 0
    source_id: int = 0
    should_apply: bool = False


@event_type
class SetpointConfigReply(Event):
    """``SetpointConfigReply`` (1.18+): PX4's answer to a ``SetpointConfig``."""

    kind: ClassVar[str] = "setpoint_config_reply"

    setpoint_type: int = 0
    source_id: int = 0
    result: int = 0
    origin: Origin = "vehicle"


EXTERNAL_MODE_TYPES: tuple[type[Event], ...] = (
    ExtComponentRequest,
    ExtComponentReply,
    ArmingCheckRequest,
    ArmingCheckReply,
    ExtComponentUnregister,
    SetpointConfig,
    SetpointConfigReply,
)


KEEPALIVE_ROS: tuple[type[Event], ...] = (ControlMode, LegacyControlMode)
KEEPALIVE_TYPES: tuple[type[Event], ...] = (*KEEPALIVE_ROS, *MAVLINK_SETPOINTS)

ALL_EVENT_TYPES: tuple[type[Event], ...] = (
    ControlMode,
    LegacyControlMode,
    *PX4_SETPOINTS,
    PositionSetpointTriplet,
    *MAVLINK_SETPOINTS,
    SetActuatorControlTarget,
    VehicleStatus,
    VehicleControlModeStatus,
    FailsafeFlags,
    ManualControl,
    LandDetected,
    Command,
    CommandAck,
    Parameter,
    VehicleInfo,
    StatusText,
    VehiclePosition,
    Dropout,
    *EXTERNAL_MODE_TYPES,
)

EVENT_BY_KIND: dict[str, type[Event]] = {cls.kind: cls for cls in ALL_EVENT_TYPES}


def is_keepalive(event: Event) -> bool:
    """Is this a keep-alive message as the docs define it (OCM on ROS 2, a setpoint on MAVLink)?"""
    return isinstance(event, KEEPALIVE_TYPES)


def event_to_dict(event: Event) -> dict[str, Any]:
    """A JSON-friendly dict of the event (``kind`` first); NaN stays NaN (``float``)."""
    out: dict[str, Any] = {"kind": event.kind}
    for f in fields(event):
        value = getattr(event, f.name)
        if isinstance(value, Where):
            value = {"topic": value.topic, "index": value.index, "offset": value.offset}
        elif isinstance(value, frozenset):
            value = sorted(value)
        elif isinstance(value, tuple):
            value = list(value)
        out[f.name] = value
    return out


def event_from_dict(data: dict[str, Any]) -> Event:
    """Build an event from ``event_to_dict`` output or a hand-written example (rule pages)."""
    data = dict(data)
    cls = EVENT_BY_KIND[data.pop("kind")]
    kwargs: dict[str, Any] = {}
    names = {f.name for f in fields(cls)}
    for key, value in data.items():
        if key not in names:
            raise ValueError(f"{cls.__name__} has no field {key!r}")
        if key == "where" and isinstance(value, dict):
            value = Where(**value)
        elif key == "where" and isinstance(value, str):
            value = Where(value)
        elif key == "enabled":
            value = frozenset(value)
        elif isinstance(value, list):
            value = tuple(float("nan") if v == "nan" else v for v in value)
        elif value == "nan":
            value = math.nan
        kwargs[key] = value
    return cls(**kwargs)
