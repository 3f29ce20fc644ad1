"""The official example clients, as state machines that say what they publish each cycle.

Each client is rewritten from its source's behaviour (README.md names the file and commit): its
timer period, what it publishes in which order, the field values it sets (and the ones it leaves
at their zero-initialised defaults), and what it reads back from the vehicle. ``cycle`` returns
the messages of one timer callback as ``Pub`` records; the driver (``runs.py``) sends PX4 their
MAVLink equivalent (``to_mavlink``) and keeps them as the client's side of the recording.

Topics are the ones the example uses. Fields are plain JSON values; NaN is kept as NaN.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from px4link import VehicleView

NAN = math.nan
OFFBOARD_MAIN = 6
AUTO_MAIN, LOITER_SUB, TAKEOFF_SUB, LAND_SUB = 4, 3, 2, 6

OCM = "/fmu/in/offboard_control_mode"
TRAJ = "/fmu/in/trajectory_setpoint"
CMD = "/fmu/in/vehicle_command"
GOTO = "/fmu/in/goto_setpoint"
CONFIG = "/fmu/in/config_control_setpoints"
ROVER_SPEED = "/fmu/in/rover_speed_setpoint"
ROVER_ATT = "/fmu/in/rover_attitude_setpoint"
MAVROS_POSE = "/mavros/setpoint_position/local"
MAVROS_SET_MODE = "/mavros/set_mode"
MAVROS_ARMING = "/mavros/cmd/arming"
"""Services: the driver sends what MAVROS sends for them; ``rosbag record`` never records them."""

VEHICLE_CMD_DO_SET_MODE = 176
VEHICLE_CMD_COMPONENT_ARM_DISARM = 400
VEHICLE_CMD_NAV_LAND = 21


@dataclass
class Pub:
    """One message a client published at PX4 time ``t_us``: topic and fields."""

    t_us: int
    topic: str
    fields: dict[str, Any]

    def to_json(self) -> dict[str, Any]:
        return {"t_us": self.t_us, "topic": self.topic, "fields": self.fields}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Pub:
        return cls(int(data["t_us"]), str(data["topic"]), dict(data["fields"]))


def ocm(t_us: int, **flags: bool) -> Pub:
    """OffboardControlMode with the given flags true (``timestamp`` set by the caller)."""
    names = ("position", "velocity", "acceleration", "attitude", "body_rate")
    return Pub(t_us, OCM, {name: bool(flags.get(name, False)) for name in names})


def trajectory(
    t_us: int,
    position: tuple[float, float, float],
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0),
    acceleration: tuple[float, float, float] = (0.0, 0.0, 0.0),
    yaw: float = 0.0,
    yawspeed: float = 0.0,
) -> Pub:
    """TrajectorySetpoint; the defaults are a zero-initialised message (``msg{}`` in C++,
    ``TrajectorySetpoint()`` in Python), not NaN."""
    return Pub(
        t_us,
        TRAJ,
        {
            "position": list(position),
            "velocity": list(velocity),
            "acceleration": list(acceleration),
            "jerk": [0.0, 0.0, 0.0],
            "yaw": yaw,
            "yawspeed": yawspeed,
        },
    )


def command(t_us: int, cmd: int, param1: float = 0.0, param2: float = 0.0) -> Pub:
    """VehicleCommand as px4_ros_com fills it: target 1/1, source 1/1, from_external."""
    return Pub(
        t_us,
        CMD,
        {
            "command": cmd,
            "param1": param1,
            "param2": param2,
            "target_system": 1,
            "target_component": 1,
            "source_system": 1,
            "source_component": 1,
            "from_external": True,
        },
    )


def with_timestamp(pub: Pub, key: str = "timestamp") -> Pub:
    """The client stamps the message with its clock (``get_clock()->now()`` in µs): here the
    publish time; ``build.py`` turns it into the wall-clock value of the recording."""
    pub.fields[key] = pub.t_us
    return pub


class Client:
    """A timer-driven example client."""

    period_us: int = 100_000
    done: bool = False

    def cycle(self, now_us: int, view: VehicleView) -> list[Pub]:
        raise NotImplementedError


# ---------------------------------------------------------------------------------------------
# PX4/px4_ros_com src/examples/offboard/offboard_control.cpp


@dataclass
class OffboardControlCpp(Client):
    """100 ms timer; at the 11th callback DO_SET_MODE(1, 6) and arm, then OCM (position) and the
    trajectory setpoint (position, yaw -3.14), every cycle from the first, stamped with the node
    clock. Variants for the hazard recordings change one thing each (see ``runs.py``)."""

    position: tuple[float, float, float] = (0.0, 0.0, -5.0)
    yaw: float = -3.14
    stall: tuple[float, float] | None = None
    """Seconds after the start during which the timer does not run (a blocked executor)."""
    velocity_from: float | None = None
    """From this many seconds, the velocity version: OCM velocity, TS velocity set."""
    velocity: tuple[float, float, float] = (1.0, 0.0, 0.0)
    velocity_position: tuple[float, float, float] | None = (0.0, 0.0, 0.0)
    """The TS position the velocity version leaves: zeros (``msg{}``) or NaN (None)."""
    planner: Any = None
    """A callable ``(seconds since velocity_from) -> velocity``: a planner's output."""
    send_mode_switch: bool = True
    send_stream: bool = True
    counter: int = 0
    start_us: int | None = None
    period_us: int = 100_000

    def cycle(self, now_us: int, view: VehicleView) -> list[Pub]:
        if self.start_us is None:
            self.start_us = now_us
        elapsed = (now_us - self.start_us) / 1e6
        if self.stall is not None and self.stall[0] <= elapsed < self.stall[1]:
            return []
        out: list[Pub] = []
        if self.counter == 10 and self.send_mode_switch:
            out.append(with_timestamp(command(now_us, VEHICLE_CMD_DO_SET_MODE, 1, 6)))
            out.append(with_timestamp(command(now_us, VEHICLE_CMD_COMPONENT_ARM_DISARM, 1.0)))
        if self.send_stream:
            if self.velocity_from is not None and elapsed >= self.velocity_from:
                velocity = self.velocity
                if self.planner is not None:
                    velocity = self.planner(elapsed - self.velocity_from)
                position = self.velocity_position or (NAN, NAN, NAN)
                out.append(with_timestamp(ocm(now_us, velocity=True)))
                out.append(with_timestamp(trajectory(now_us, position, velocity, yaw=self.yaw)))
            else:
                out.append(with_timestamp(ocm(now_us, position=True)))
                out.append(with_timestamp(trajectory(now_us, self.position, yaw=self.yaw)))
        if self.counter < 11:
            self.counter += 1
        return out


# ---------------------------------------------------------------------------------------------
# PX4/px4_ros_com src/examples/offboard_py/offboard_control.py (takeoff and land)


@dataclass
class OffboardControlPy(Client):
    """100 ms timer: OCM (position) every cycle; at the 11th DO_SET_MODE(1, 6) then arm; a
    trajectory setpoint (0, 0, -5), yaw 1.57079, only while the vehicle reports OFFBOARD and is
    below 5 m; at 5 m NAV_LAND, and the node exits (the stream stops)."""

    takeoff_height: float = -5.0
    counter: int = 0
    period_us: int = 100_000

    def cycle(self, now_us: int, view: VehicleView) -> list[Pub]:
        out = [with_timestamp(ocm(now_us, position=True))]
        if self.counter == 10:
            out.append(with_timestamp(command(now_us, VEHICLE_CMD_DO_SET_MODE, 1.0, 6.0)))
            out.append(with_timestamp(command(now_us, VEHICLE_CMD_COMPONENT_ARM_DISARM, 1.0)))
        if view.z > self.takeoff_height and view.main_mode == OFFBOARD_MAIN:
            position = (0.0, 0.0, self.takeoff_height)
            out.append(with_timestamp(trajectory(now_us, position, yaw=1.57079)))
        elif view.z <= self.takeoff_height:
            out.append(with_timestamp(command(now_us, VEHICLE_CMD_NAV_LAND)))
            self.done = True
        if self.counter < 11:
            self.counter += 1
        return out


# ---------------------------------------------------------------------------------------------
# Jaeyoung-Lim/px4-offboard px4_offboard/offboard_control.py (the docs' ROS 2 Python example)


@dataclass
class CircleOffboard(Client):
    """20 ms timer: OCM (position) every cycle, stamped; while the vehicle is in OFFBOARD and
    armed, a trajectory setpoint on a circle of ``radius`` m at ``omega`` rad/s (theta advances by
    omega * 0.02 per cycle), z = -altitude, no timestamp (0), other fields zero. The example never
    switches mode or arms: the pilot does it from the ground station. Parameters and namespace
    are those of its launch file (radius 10, altitude 5, omega 0.5; ``px4_offboard``)."""

    radius: float = 10.0
    omega: float = 0.5
    altitude: float = 5.0
    namespace: str = "/px4_offboard"
    theta: float = 0.0
    period_us: int = 20_000

    def cycle(self, now_us: int, view: VehicleView) -> list[Pub]:
        control_mode = with_timestamp(ocm(now_us, position=True))
        control_mode.topic = self.namespace + OCM
        out = [control_mode]
        if view.main_mode == OFFBOARD_MAIN and view.armed:
            x = self.radius * math.cos(self.theta)
            y = self.radius * math.sin(self.theta)
            pub = trajectory(now_us, (x, y, -self.altitude))
            pub.fields["timestamp"] = 0
            pub.topic = self.namespace + TRAJ
            out.append(pub)
            self.theta += self.omega * 0.02
        return out


# ---------------------------------------------------------------------------------------------
# MAVROS offb_node (PX4 user guide, docs/en/ros/mavros_offboard_cpp.md and _python.md)


@dataclass
class MavrosOffbNode(Client):
    """20 Hz loop: 100 poses (ENU x 0, y 0, z 2; orientation and header left at their zero
    defaults) before anything else; then every cycle, if the state is not OFFBOARD and 5 s have
    passed since the last request, ``set_mode`` OFFBOARD; else, if not armed and 5 s have
    passed, ``arming`` true; then the pose. The state is MAVROS's ``/mavros/state`` (one per
    HEARTBEAT)."""

    z: float = 2.0
    pre_stream: int = 100
    stall: tuple[float, float] | None = None
    sent: int = 0
    last_request_us: int | None = None
    start_us: int | None = None
    period_us: int = 50_000

    def cycle(self, now_us: int, view: VehicleView) -> list[Pub]:
        if self.start_us is None:
            self.start_us = now_us
        elapsed = (now_us - self.start_us) / 1e6
        if self.stall is not None and self.stall[0] <= elapsed < self.stall[1]:
            return []
        out: list[Pub] = []
        if self.sent >= self.pre_stream:
            if self.last_request_us is None:
                self.last_request_us = now_us
            waited = now_us - self.last_request_us > 5_000_000
            if view.main_mode != OFFBOARD_MAIN and waited:
                request = {"base_mode": 0, "custom_mode": "OFFBOARD"}
                out.append(Pub(now_us, MAVROS_SET_MODE, request))
                self.last_request_us = now_us
            elif not view.armed and waited:
                out.append(Pub(now_us, MAVROS_ARMING, {"value": True}))
                self.last_request_us = now_us
        out.append(Pub(now_us, MAVROS_POSE, {"position": [0.0, 0.0, self.z]}))
        self.sent += 1
        return out


# ---------------------------------------------------------------------------------------------
# Auterion/px4-ros2-interface-lib examples/cpp/modes/goto (an external mode)


@dataclass
class GotoMode(Client):
    """The library's 50 Hz setpoint timer while the mode is active: a GotoSetpoint (timestamp 0,
    PX4 stamps it) per cycle; the state machine of the example (settle at the start, 20 m north
    facing the way, 30 m east while spinning with scaled speed limits, back to the start facing
    the north-west corner), then ``completed`` once while it keeps holding the start. Positions
    and heading are read from the vehicle."""

    state: str = "settle"
    start: tuple[float, float, float] | None = None
    spin_heading: float | None = None
    active: bool = False
    completed: bool = False
    period_us: int = 20_000

    def reached(self, view: VehicleView, target: tuple[float, float, float]) -> bool:
        error = math.dist((view.x, view.y, view.z), target)
        return error < 0.5 and abs(view.vz) < 0.3

    def cycle(self, now_us: int, view: VehicleView) -> list[Pub]:
        # the library activates the mode when vehicle_status shows it selected and armed (here
        # OFFBOARD stands in for EXTERNAL1, see README.md) and updates at once
        if not self.active:
            self.active = view.main_mode == OFFBOARD_MAIN and view.armed
            if not self.active:
                return []
        if self.start is None:
            self.start = (view.x, view.y, view.z)
        sx, sy, sz = self.start
        fields: dict[str, Any]
        out: list[Pub] = []
        if self.state == "settle":
            fields = goto_fields(self.start)
            if self.reached(view, self.start):
                self.state = "north"
        elif self.state == "north":
            target = (sx + 20.0, sy, sz)
            dx, dy = target[0] - view.x, target[1] - view.y
            heading = math.atan2(dy, dx) if math.hypot(dx, dy) >= 0.1 else None
            fields = goto_fields(target, heading)
            if self.reached(view, target):
                self.state = "east"
        elif self.state == "east":
            target = (sx + 20.0, sy + 30.0, sz)
            scale = min(math.hypot(target[0] - view.x, target[1] - view.y) / 30.0, 1.0)
            if self.spin_heading is None:
                self.spin_heading = view.heading
            if not self.reached(view, target):
                self.spin_heading += math.radians(40.0 * scale + (1 - scale) * 20.0) * 0.02
            fields = goto_fields(
                target,
                self.spin_heading,
                5.0 * scale + (1 - scale) * 1.0,
                3.0 * scale + (1 - scale) * 0.5,
                math.radians(45.0 * scale + (1 - scale) * 25.0),
            )
            if self.reached(view, target):
                self.state = "southwest"
        else:
            poi = (sx + 20.0, sy)
            heading = math.atan2(poi[1] - view.y, poi[0] - view.x)
            fields = goto_fields(self.start, heading)
            if self.reached(view, self.start) and not self.completed:
                # completed() once; the mode stays active and keeps updating (the example's
                # last state calls update before it checks)
                self.completed = True
                out.append(Pub(now_us, "/fmu/in/mode_completed", {"nav_state": 23, "result": 0}))
        return [Pub(now_us, GOTO, fields), *out]


def goto_fields(
    position: tuple[float, float, float],
    heading: float | None = None,
    max_horizontal: float | None = None,
    max_vertical: float | None = None,
    max_heading_rate: float | None = None,
) -> dict[str, Any]:
    """GotoSetpoint as the library fills it: unset options are 0 with their flag false."""
    return {
        "timestamp": 0,
        "position": list(position),
        "flag_control_heading": heading is not None,
        "heading": heading or 0.0,
        "flag_set_max_horizontal_speed": max_horizontal is not None,
        "max_horizontal_speed": max_horizontal or 0.0,
        "flag_set_max_vertical_speed": max_vertical is not None,
        "max_vertical_speed": max_vertical or 0.0,
        "flag_set_max_heading_rate": max_heading_rate is not None,
        "max_heading_rate": max_heading_rate or 0.0,
    }


# ---------------------------------------------------------------------------------------------
# Rover: px4_ros_com's structure with the docs' rover setpoints (PX4 1.16+)


@dataclass
class RoverSpeedAttitude(Client):
    """px4_ros_com's 100 ms timer, 10 cycles, DO_SET_MODE and arm, with the docs' "Speed +
    Attitude" combination (OCM velocity; RoverSpeedSetpoint, RoverAttitudeSetpoint) filled as
    px4-ros2-interface-lib's RoverSpeedAttitudeSetpointType does (timestamp 0, speed_body_y NaN).
    ``trajectory_yaw`` is the hazard: the same client steering an Ackermann rover through a
    TrajectorySetpoint yaw with the attitude flag, which the Ackermann modules ignore."""

    speed: float = 1.0
    yaw: float = 1.57
    trajectory_yaw: bool = False
    counter: int = 0
    period_us: int = 100_000

    def cycle(self, now_us: int, view: VehicleView) -> list[Pub]:
        out: list[Pub] = []
        if self.counter == 10:
            out.append(with_timestamp(command(now_us, VEHICLE_CMD_DO_SET_MODE, 1, 6)))
            out.append(with_timestamp(command(now_us, VEHICLE_CMD_COMPONENT_ARM_DISARM, 1.0)))
        if self.trajectory_yaw:
            out.append(with_timestamp(ocm(now_us, attitude=True)))
            pub = trajectory(now_us, (NAN, NAN, NAN), (NAN, NAN, NAN), (NAN, NAN, NAN))
            pub.fields["yaw"] = self.yaw
            pub.fields["yawspeed"] = NAN
            out.append(with_timestamp(pub))
        else:
            out.append(with_timestamp(ocm(now_us, velocity=True)))
            out.append(
                Pub(
                    now_us,
                    ROVER_SPEED,
                    {"timestamp": 0, "speed_body_x": self.speed, "speed_body_y": NAN},
                )
            )
            out.append(Pub(now_us, ROVER_ATT, {"timestamp": 0, "yaw_setpoint": self.yaw}))
        if self.counter < 11:
            self.counter += 1
        return out


# ---------------------------------------------------------------------------------------------
# What PX4 receives for these messages over MAVLink (the bundles have no ROS 2 bridge)


IGNORE_YAW, IGNORE_YAW_RATE = 1024, 2048


def trajectory_mask(fields: dict[str, Any]) -> tuple[int, dict[str, Any]]:
    """SET_POSITION_TARGET_LOCAL_NED ``type_mask`` and values that make PX4's receiver publish
    the same trajectory setpoint: a NaN component's ignore bit is set (its value sent as 0)."""
    mask = 0
    values: dict[str, Any] = {}
    groups = (
        ("position", ("x", "y", "z"), 0),
        ("velocity", ("vx", "vy", "vz"), 3),
        ("acceleration", ("afx", "afy", "afz"), 6),
    )
    for key, names, bit in groups:
        for i, name in enumerate(names):
            value = float(fields[key][i])
            if math.isnan(value):
                mask |= 1 << (bit + i)
                value = 0.0
            values[name] = value
    for key, bit in (("yaw", IGNORE_YAW), ("yawspeed", IGNORE_YAW_RATE)):
        value = float(fields[key])
        if math.isnan(value):
            mask |= bit
            value = 0.0
        values["yaw" if key == "yaw" else "yaw_rate"] = value
    return mask, values
