"""Compose the concept strategies into whole streams (``scenarios``), per transport.

* ``ros2``: ``ControlMode`` keep-alive + PX4 setpoint topics + ``VehicleCommand`` (and the
  vehicle's ``VehicleCommandAck``), as ``/fmu/in`` and ``/fmu/out`` of an MCAP recording;
* ``mavlink``: SET_POSITION_TARGET_* / SET_ATTITUDE_TARGET from the companion (they are the
  keep-alive), COMMAND_LONG and the autopilot's COMMAND_ACK, as in a tlog;
* ``mavros``: the same MAVLink setpoints with ``transport="mavros"`` and ``/mavros/state`` (a
  MAVROS bag has no commands: mode changes are service calls, only the state shows them).

The vehicle's side (acks, MAVROS state) is what the gate model predicts for the sent side
(``echo``): a recording of a vehicle that behaves as the model says. Events are built exactly as
the readers give them back (sender ids, ``from_external``, sender timestamps), so the round trip
through a writer and a reader can be compared field by field.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from hypothesis import strategies as st

from fuzzoff import events as ev
from fuzzoff import releases
from fuzzoff.formats import px4_msgs
from fuzzoff.fuzz import strategies as fs
from fuzzoff.fuzz.scenario import AUTOPILOT, COMPANION, TRANSPORTS, Scenario, TransportName
from fuzzoff.gate import GateModel
from fuzzoff.gate.params import default_params, loss_timeout
from fuzzoff.modes import mavros_mode_to_nav_state, nav_state_to_mavros_mode
from fuzzoff.profiles import Profile, is_rover
from fuzzoff.releases import PX4Profile

MIN_STEP = 0.0001
"""Distinct receive times: events never share a timestamp (the readers' order for equal
timestamps is the file's, which a writer need not keep)."""

MODE_POSCTL = (1.0, 3.0)
"""DO_SET_MODE params for POSCTL (custom main mode 3)."""
STATUS_STEP = 0.05
"""How often the MAVROS state echo looks at the model between messages."""


def _cmd(t: float, command: int, params: Sequence[float], transport: TransportName) -> ev.Command:
    p = (list(params) + [0.0] * 7)[:7]
    full = (p[0], p[1], p[2], p[3], p[4], p[5], p[6])
    if transport == "ros2":
        return ev.Command(
            t=t,
            command=command,
            params=full,
            sender_time_us=round(t * 1e6),
            target_system=AUTOPILOT[0],
            target_component=AUTOPILOT[1],
            source_system=0,
            source_component=0,
            from_external=True,
            transport="ros2",
        )
    return ev.Command(
        t=t,
        vehicle="1",
        command=command,
        params=full,
        target_system=AUTOPILOT[0],
        target_component=AUTOPILOT[1],
        source_system=COMPANION[0],
        source_component=COMPANION[1],
        from_external=True,
        transport="mavlink",
        message="COMMAND_LONG",
    )


def commands(plan: fs.CommandPlan, transport: TransportName) -> list[ev.Command]:
    """The plan's commands (none for MAVROS: its mode changes are service calls)."""
    out: list[ev.Command] = []
    if plan.arm is not None:
        out.append(_cmd(plan.arm, ev.MAV_CMD_COMPONENT_ARM_DISARM, (1.0,), transport))
    if plan.switch is not None:
        if plan.set_nav_state:
            out.append(_cmd(plan.switch, ev.VEHICLE_CMD_SET_NAV_STATE, (14.0,), transport))
        else:
            out.append(_cmd(plan.switch, ev.MAV_CMD_DO_SET_MODE, (1.0, 6.0), transport))
    if plan.leave is not None:
        out.append(_cmd(plan.leave, ev.MAV_CMD_DO_SET_MODE, MODE_POSCTL, transport))
    if plan.disarm is not None:
        out.append(_cmd(plan.disarm, ev.MAV_CMD_COMPONENT_ARM_DISARM, (0.0,), transport))
    return out


def settle(events: Sequence[ev.Event], *, from_zero: bool = True) -> list[ev.Event]:
    """Sorted, starting at 0 (a recording's clock starts at its first message), 0.1 ms
    resolution, strictly increasing. ``from_zero=False`` keeps the clock where it is (a
    perturbation that delays the first message must not move the others earlier)."""
    ordered = sorted(events, key=lambda e: e.t)
    if not ordered:
        return []
    t0 = ordered[0].t if from_zero else 0.0
    out: list[ev.Event] = []
    last = -1.0
    for e in ordered:
        t = round(max(e.t - t0, last + MIN_STEP), 4)
        if t != e.t:
            e = _retime(e, t)
        out.append(e)
        last = t
    return out


def _retime(e: ev.Event, t: float) -> ev.Event:
    """Move ``e`` to ``t``; a sender stamp that tracked the send time moves with it."""
    if e.sender_time_us is not None and e.sender_time_us == round(e.t * 1e6):
        if e.kind.startswith("set_"):  # MAVLink time_boot_ms: millisecond resolution
            return replace(e, t=t, sender_time_us=round(t * 1e3) * 1000)
        return replace(e, t=t, sender_time_us=round(t * 1e6))
    return replace(e, t=t)


# ----------------------------------------------------------------------------- the vehicle

ACCEPT = {"request_accepted", "arm_accepted", "disarmed", "mode"}
REJECT = {"request_rejected", "arm_rejected", "disarm_rejected"}


def echo(
    sent: Sequence[ev.Event],
    px4: PX4Profile,
    vehicle: str,
    params: dict[str, float],
    *,
    acks: bool,
    status: bool,
    transport: TransportName,
) -> list[ev.Event]:
    """The vehicle's answers the gate model predicts: a COMMAND_ACK per command (two for a
    MAVLink mode switch on 1.16/1.17, gate.md#acks), and for MAVROS the state at 1 Hz and at
    each change."""
    profile = Profile(px4=px4, vehicle=vehicle, px4_detected=True, vehicle_detected=True)
    vid = "1" if transport == "mavlink" else ""
    model = GateModel(profile, params, vid, armed=False)  # the simulated vehicle boots disarmed
    out: list[ev.Event] = []
    last_state: tuple[int | None, bool | None] | None = None
    next_beat = 0.0
    clock = 0.0

    def note(t: float) -> None:
        nonlocal last_state
        if (model.nav_state, model.armed) != last_state:
            last_state = (model.nav_state, model.armed)
            out.append(_status(t + 0.003, model, vid))

    for event in sent:
        if status:
            # The state changes between messages too (a loss failsafe): look at 20 Hz.
            while clock + STATUS_STEP < event.t:
                clock += STATUS_STEP
                model.feed(ev.Dropout(t=clock, vehicle=vid))  # advances the clock only
                note(clock)
                if clock >= next_beat:
                    out.append(_status(clock + 0.0002, model, vid))
                    next_beat += 1.0
        transitions = model.feed(event)
        clock = max(clock, event.t)
        if isinstance(event, ev.Command) and acks:
            out += _acks(event, transitions, profile.release.acks_switch_twice, transport, vid)
        if status:
            note(event.t)
    return out


def _status(t: float, model: GateModel, vid: str) -> ev.VehicleStatus:
    nav = model.nav_state if model.nav_state is not None else 2
    # /mavros/state names a mode; the writer knows no name for some (TERMINATION, DESCEND):
    # the state shows what the name reads back as.
    nav = mavros_mode_to_nav_state(nav_state_to_mavros_mode(nav)) or 0
    return ev.VehicleStatus(
        t=t, vehicle=vid, nav_state=nav, mode=nav_state_to_mavros_mode(nav), armed=model.armed
    )


def _acks(
    cmd: ev.Command,
    transitions: Sequence[Any],
    twice: bool,
    transport: TransportName,
    vid: str,
) -> list[ev.Event]:
    ours = [tr for tr in transitions if tr.cause is cmd]
    rejected = any(tr.what in REJECT or (tr.what == "mode" and tr.reason) for tr in ours)
    result = 1 if rejected else 0
    out: list[ev.Event] = []
    stamp = transport == "ros2"

    def ack(t: float, res: int) -> ev.CommandAck:
        return ev.CommandAck(
            t=t,
            vehicle=vid,
            command=cmd.command,
            result=res,
            target_system=0 if stamp else COMPANION[0],
            target_component=0 if stamp else COMPANION[1],
            sender_time_us=round(t * 1e6) if stamp else None,
        )

    if transport == "mavlink" and cmd.is_mode_switch and twice:
        out.append(ack(cmd.t + 0.002, 0))
    out.append(ack(cmd.t + 0.008, result))
    return out


# ----------------------------------------------------------------------------- per transport


_MESSAGE = {
    "trajectory": "TrajectorySetpoint",
    "attitude": "VehicleAttitudeSetpoint",
    "rates": "VehicleRatesSetpoint",
    "rover_position": "RoverPositionSetpoint",
    "rover_speed": "RoverSpeedSetpoint",
    "rover_attitude": "RoverAttitudeSetpoint",
    "rover_rate": "RoverRateSetpoint",
    "rover_throttle": "RoverThrottleSetpoint",
    "rover_steering": "RoverSteeringSetpoint",
}


def _published(kind: str, px4: PX4Profile) -> bool:
    """Does the release's px4_msgs have this setpoint's message (rover topics vary)?"""
    return px4_msgs.definition(_msg_folder(px4), _MESSAGE[kind]) is not None


def _msg_folder(px4: PX4Profile) -> str:
    """The px4_msgs folder of the release (main's for a release before ROS 2)."""
    return releases.get(px4).msg_folder or "main"


_WIRE_NAME = {"normalized_steering_angle": "normalized_steering_setpoint"}
"""Event fields whose message field was renamed in a release (1.17's RoverSteeringSetpoint)."""


def _carried(kind: str, px4: PX4Profile, values: fs.RoverValues) -> fs.RoverValues:
    """``values`` with NaN for the fields the release's message does not have (1.17 dropped
    RoverSteeringSetpoint's ``normalized_speed_diff``): a recording of that release cannot
    hold them, and its reader gives NaN, as PX4 would never see them."""
    if kind not in _MESSAGE:
        return values
    name = _MESSAGE[kind]
    text = px4_msgs.definition(_msg_folder(px4), name)
    if text is None:
        return values
    wire = px4_msgs.field_names(px4_msgs.type_name(name), text)
    return {k: v if k in wire or _WIRE_NAME.get(k) in wire else fs.NAN for k, v in values.items()}


def _ros2_setpoint_kinds(vehicle: str, px4: PX4Profile) -> list[str]:
    kinds = ["trajectory", "trajectory", "attitude", "rates", "none"]
    if is_rover(vehicle) and releases.get(px4).rover_setpoints:
        kinds += [k for k in fs.ROVER_KINDS if _published(k, px4)] * 2
    return kinds


_ROS2_BUILD: dict[str, Callable[..., ev.Event]] = {
    "trajectory": ev.TrajectorySetpoint,
    "attitude": ev.AttitudeSetpoint,
    "rates": ev.RatesSetpoint,
    "rover_position": ev.RoverPositionSetpoint,
    "rover_speed": ev.RoverSpeedSetpoint,
    "rover_attitude": ev.RoverAttitudeSetpoint,
    "rover_rate": ev.RoverRateSetpoint,
    "rover_throttle": ev.RoverThrottleSetpoint,
    "rover_steering": ev.RoverSteeringSetpoint,
}


@st.composite
def ros2_sent(draw: st.DrawFn, px4: PX4Profile, vehicle: str, times: list[float]) -> list[ev.Event]:
    """Keep-alive and setpoints of a ROS 2 companion (``/fmu/in``)."""
    flags = draw(fs.control_modes(px4))
    skew = draw(fs.clock_skews())
    stamps = skew.stamp(times)
    out: list[ev.Event] = [
        ev.ControlMode(t=t, sender_time_us=s, **flags) for t, s in zip(times, stamps, strict=True)
    ]
    choices = _ros2_setpoint_kinds(vehicle, px4)
    # A rover program publishes a combination of rover setpoints (OFB502, OFB504).
    most = 3 if is_rover(vehicle) else 1
    any_kinds = st.lists(st.sampled_from(choices), min_size=1, max_size=most, unique=True)
    rover_path = is_rover(vehicle) and releases.get(px4).rover_setpoints
    if rover_path and draw(st.booleans()) and times:
        return draw(_rover_program_series(px4, times, stamps))
    if rover_path:
        combos = [c for c in fs.ROVER_COMBINATIONS if all(_published(k, px4) for k in c)]
        kinds = draw(
            st.one_of(any_kinds, st.sampled_from(combos).map(list)) if combos else any_kinds
        )
    else:
        kinds = draw(any_kinds)
    if not times:
        return out
    for offset, kind in enumerate(k for k in kinds if k != "none"):
        out += draw(_setpoint_series(kind, times, 0.001 * (offset + 1), px4))
    return out


def _control_mode_layout(px4: PX4Profile) -> fs.ControlModeFlags:
    newer = releases.get(px4).control_mode == "thrust_and_torque"
    return fs.ControlModeFlags(layout="thrust_and_torque" if newer else "actuator")


@st.composite
def _rover_program_series(
    draw: st.DrawFn, px4: PX4Profile, times: list[float], stamps: list[int]
) -> list[ev.Event]:
    """A rover program's cycle (``fs.rover_programs``), or the deprecated ``TrajectorySetpoint``
    under one of the flags the docs give it (position, velocity, attitude: yaw, which an
    Ackermann rover cannot take), each message after the keep-alive."""
    flags = _control_mode_layout(px4)
    if draw(st.integers(0, 2)) == 0:
        flag = draw(st.sampled_from(("position", "velocity", "attitude")))
        trajectory = draw(fs.trajectory_setpoints())
        if flag == "attitude":  # the yaw the docs make the one active field (OFB505)
            trajectory = {**trajectory, "yaw": draw(fs.f32)}
        published: list[tuple[str, fs.SetpointValues]] = [("trajectory", trajectory)]
    else:
        program = draw(fs.rover_programs([k for k in fs.ROVER_KINDS if _published(k, px4)]))
        flag = program.flag
        published = [(k, _carried(k, px4, v)) for k, v in program.published]
    flags[flag] = True  # type: ignore[literal-required]  # a name of OCM_FLAGS_115
    out: list[ev.Event] = [
        ev.ControlMode(t=t, sender_time_us=s, **flags) for t, s in zip(times, stamps, strict=True)
    ]
    for offset, (kind, values) in enumerate(published):
        out += draw(_setpoint_series(kind, times, 0.001 * (offset + 1), px4, values))
    return out


@st.composite
def _setpoint_series(
    draw: st.DrawFn,
    kind: str,
    times: list[float],
    lag: float,
    px4: PX4Profile,
    given: fs.SetpointValues | None = None,
) -> list[ev.Event]:
    """One setpoint topic following the keep-alive by ``lag``, maybe starting late or stopping
    early (stale setpoints under a live keep-alive: OFB104), frozen or moving; ``given``: its
    values (else drawn)."""
    values: fs.SetpointValues
    if given is not None:
        values = given
    elif kind == "trajectory":
        values = draw(fs.trajectory_setpoints())
    elif kind == "attitude":
        values = draw(fs.attitude_setpoints())
    elif kind == "rates":
        values = draw(fs.rates_setpoints())
    else:
        _, rover = draw(fs.rover_setpoints(kind))
        values = _carried(kind, px4, rover)
    nth = fs.frozen_or_moving(values) if draw(st.booleans()) else (lambda i: values)
    whole = draw(st.sampled_from(["whole", "whole", "late", "early"]))
    start = draw(st.integers(0, len(times) - 1)) if whole == "late" else 0
    stop = draw(st.integers(start, len(times))) if whole == "early" else len(times)
    build = _ROS2_BUILD[kind]
    out: list[ev.Event] = []
    for i in range(start, stop):
        t = times[i] + lag
        out.append(build(t=t, sender_time_us=round(t * 1e6), **nth(i)))
    return out


_MAV_BUILD: dict[str, type[ev.MavlinkTarget]] = {
    "set_position_target_local_ned": ev.SetPositionTargetLocal,
    "set_position_target_global_int": ev.SetPositionTargetGlobal,
    "set_attitude_target": ev.SetAttitudeTarget,
}


@st.composite
def mavlink_sent(
    draw: st.DrawFn, times: list[float], transport: TransportName, vehicle: str | None = None
) -> list[ev.Event]:
    """MAVLink setpoints (each one a keep-alive) from the companion, shaped for ``vehicle``."""
    kind, values = draw(fs.vehicle_setpoints(vehicle))
    if transport == "mavros" and "thrust" in values:
        # MAVROS clamps thrust to [0, 1] before it is sent (rosbag1/writer.py): what PX4 gets.
        thrust = float(values["thrust"])
        values["thrust"] = min(max(thrust, 0.0), 1.0) if thrust == thrust else 0.0
    skew = draw(fs.clock_skews()) if transport == "mavlink" else fs.ClockSkew(0.0, 0.0, ())
    nth = fs.frozen_or_moving(values) if draw(st.booleans()) else None
    return _mavlink_series(times, transport, (kind, values), skew, nth)


def _mavlink_series(
    times: list[float],
    transport: TransportName,
    setpoint: tuple[str, dict[str, Any]],
    skew: fs.ClockSkew,
    nth: Callable[[int], Any] | None,
) -> list[ev.Event]:
    """One MAVLink setpoint per send time (``nth``: the i-th one's values; None: the same)."""
    kind, values = setpoint
    nth = nth or (lambda i: values)
    stamps = [s // 1000 * 1000 for s in skew.stamp(times)]
    build = _MAV_BUILD[kind]
    out: list[ev.Event] = []
    for i, t in enumerate(times):
        extra: dict[str, Any] = {"target_system": AUTOPILOT[0], "target_component": AUTOPILOT[1]}
        if transport == "mavlink":
            extra |= {"source_system": COMPANION[0], "source_component": COMPANION[1]}
            extra["sender_time_us"] = stamps[i] % (2**32 * 1000)
            extra["vehicle"] = "1"
        else:  # MAVROS addresses its target (tgt_system 1, tgt_component 1); ROS namespace ""
            extra["vehicle"] = ""
        out.append(build(t=t, transport=transport, **extra, **nth(i)))
    return out


VELOCITY_MASK = 0b110111000111
"""SET_POSITION_TARGET_LOCAL_NED: velocity only (position, acceleration, yaw ignored)."""


def _held_sent(
    held: fs.HeldCommand, px4: PX4Profile, vehicle: str, transport: TransportName
) -> list[ev.Event]:
    """The companion's stream of a held command: one moving setpoint, identical in every
    message, at a steady rate (``fs.held_commands``)."""
    n = int(held.duration * held.rate) + 1
    times = [round(i / held.rate, 4) for i in range(n)]
    v = held.speed
    if transport != "ros2":
        values: dict[str, Any] = {
            "type_mask": VELOCITY_MASK,
            "coordinate_frame": 1,
            "position": (0.0, 0.0, 0.0),
            "velocity": (v, 0.0, 0.0),
            "acceleration": (0.0, 0.0, 0.0),
            "yaw": 0.0,
            "yaw_rate": 0.0,
        }
        setpoint = ("set_position_target_local_ned", values)
        return _mavlink_series(times, transport, setpoint, fs.ClockSkew(0.0, 0.0, ()), None)
    flags = _control_mode_layout(px4)
    flags["velocity"] = True
    out: list[ev.Event] = [
        ev.ControlMode(t=t, sender_time_us=round(t * 1e6), **flags) for t in times
    ]
    setpoints: list[ev.Event] = []
    for t in times:
        t1 = t + 0.001
        if is_rover(vehicle) and _published("rover_speed", px4):  # 1.17+ (1.16 has none)
            setpoints.append(
                ev.RoverSpeedSetpoint(
                    t=t1, sender_time_us=round(t1 * 1e6), speed_body_x=v, speed_body_y=0.0
                )
            )
            t2 = t + 0.002
            setpoints.append(
                ev.RoverAttitudeSetpoint(t=t2, sender_time_us=round(t2 * 1e6), yaw_setpoint=0.0)
            )
        else:
            setpoints.append(
                ev.TrajectorySetpoint(
                    t=t1, sender_time_us=round(t1 * 1e6), velocity=(v, 0.0, 0.0), yaw=0.0
                )
            )
    return out + setpoints


@st.composite
def held_scenarios(
    draw: st.DrawFn, px4: PX4Profile, vehicle: str, transport: TransportName
) -> Scenario:
    """A companion that arms, switches to OFFBOARD and holds one moving command for 12-20 s
    (a frozen planner: OFB107), on the vehicle's own setpoints (a rover's speed and heading
    from 1.17, else a velocity)."""
    held = draw(fs.held_commands())
    sent = _held_sent(held, px4, vehicle, transport)
    plan = fs.CommandPlan(
        arm=round(held.switch - 0.2, 3),
        switch=held.switch,
        leave=None,
        disarm=None,
        acks=transport != "mavros",
    )
    return _assembled(px4, vehicle, transport, {}, sent, plan)


@st.composite
def scenarios(
    draw: st.DrawFn,
    px4: PX4Profile | None = None,
    vehicle: str | None = None,
    transport: TransportName | None = None,
) -> Scenario:
    """A whole stream: profile, parameters, keep-alive timing, content, commands, answers."""
    chosen: TransportName = (
        transport if transport is not None else draw(st.sampled_from(TRANSPORTS))
    )
    profile: PX4Profile = px4 if px4 is not None else draw(fs.px4_versions(chosen))
    release = releases.get(profile)
    if chosen == "ros2" and not release.control_mode_flags:
        chosen = "mavlink"  # the ROS 2 control mode does not exist before 1.13
    vehicle = vehicle or draw(fs.vehicle_types())
    params = draw(fs.gate_params(profile))
    timeout = loss_timeout(profile, default_params(profile) | params)
    times = draw(fs.keepalive_times(timeout))
    duration = times[-1] if times else 0.0
    if chosen == "ros2":
        sent = draw(ros2_sent(profile, vehicle, times))
    else:
        sent = draw(mavlink_sent(times, chosen, vehicle))
    plan = draw(fs.command_plans(duration, chosen == "ros2" and release.handles_set_nav_state))
    if chosen == "mavros":
        plan = replace(plan, acks=False)
    # One stream in eight is a held command instead, drawn last: the ordinary stream's draws
    # come first and in the same order, so a seed searches the ordinary streams as before.
    if draw(st.sampled_from((False,) * 7 + (True,))):
        return draw(held_scenarios(profile, vehicle, chosen))
    return _assembled(profile, vehicle, chosen, params, sent, plan)


def _assembled(
    profile: PX4Profile,
    vehicle: str,
    chosen: TransportName,
    params: dict[str, float],
    sent: list[ev.Event],
    plan: fs.CommandPlan,
) -> Scenario:
    """The companion's stream with its commands and the vehicle's answers, as recorded."""
    sent = settle([*sent, *commands(plan, chosen)])
    answers = echo(
        sent,
        profile,
        vehicle,
        params,
        acks=plan.acks,
        status=chosen == "mavros",
        transport=chosen,
    )
    stream = settle([*sent, *answers])
    if chosen == "mavros":
        stream = [e for e in stream if not isinstance(e, ev.Command)]
        stream = settle(stream)
    return Scenario(
        px4=profile, vehicle=vehicle, transport=chosen, events=tuple(stream), params=params
    )
