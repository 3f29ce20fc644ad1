"""The official offboard examples as event streams, as their sources send them (issue 17).

Reproduced from the sources, with the vehicle's side as PX4 answers (gate spec 4.3, 13a):

* ``px4_ros_com`` ``src/examples/offboard/offboard_control.cpp``: a 100 ms wall timer publishes
  ``OffboardControlMode`` (position) and ``TrajectorySetpoint`` (0, 0, -5, yaw -3.14) from its first
  cycle; in the 11th it sends ``DO_SET_MODE`` (1, 6) and the arm command, then publishes;
* MAVSDK ``examples/offboard/offboard.cpp`` over ``offboard_impl.cpp``: arm, takeoff, then four
  sections (global position, attitude, NED velocity, body velocity), each ``set_*`` once, then
  ``start()``, ``set_*`` and ``sleep_for``, then ``stop()`` (setpoints stop, DO_SET_MODE to Hold);
  every ``set_*`` is sent at once and re-sent every 50 ms (the timer restarts at each call);
* the MAVROS ``offb_node`` example of PX4's user guide: ``setpoint_position/local`` (ENU z = 2)
  at 20 Hz, 100 of them before the first ``set_mode`` OFFBOARD, then ``set_mode`` or arming
  every 5 s until both are done (services are not recorded: the bag has ``/mavros/state``);
* a px4-ros2-interface-lib mode (``examples/cpp/modes/goto``): setpoints only while PX4 runs
  the registered external mode (nav_state EXTERNAL1), no ``OffboardControlMode``.

Each builder returns the events a reader produces for that recording, in time order.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from fuzzoff.events import (
    Command,
    CommandAck,
    ControlMode,
    Event,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
)

OFFBOARD, LOITER, TAKEOFF, LAND, POSCTL, EXTERNAL1 = 14, 4, 17, 18, 2, 23
DO_SET_MODE, ARM_DISARM, NAV_TAKEOFF, NAV_LAND = 176, 400, 22, 21
OFFBOARD_MODE = (1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0)
HOLD_MODE = (1.0, 4.0, 3.0, 0.0, 0.0, 0.0, 0.0)
ARM = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
EPOCH_US = 1_700_000_000_000_000
"""The companion's wall clock at the start of the recording (ROS time, microseconds)."""


def double_ack(px4: str) -> bool:
    """PX4 1.16 and 1.17 ack a MAVLink DO_SET_MODE twice (gate spec 4.3)."""
    return px4 in ("1.16", "1.17")


@dataclass
class Vehicle:
    """The vehicle's mode and arming over time, and what its status messages say."""

    nav: int
    armed: bool = False
    changes: list[tuple[float, int, bool]] = field(default_factory=list)

    def set(self, t: float, nav: int | None = None, armed: bool | None = None) -> None:
        self.nav = self.nav if nav is None else nav
        self.armed = self.armed if armed is None else armed
        self.changes.append((round(t, 6), self.nav, self.armed))

    def at(self, t: float, start: tuple[int, bool]) -> tuple[int, bool]:
        nav, armed = start
        for when, n, a in self.changes:
            if when <= t:
                nav, armed = n, a
        return nav, armed

    def statuses(
        self, start: tuple[int, bool], t_end: float, period: float, vehicle: str = ""
    ) -> list[Event]:
        """A status every ``period`` (PX4's HEARTBEAT is 1 Hz), each with the state then."""
        out: list[Event] = []
        n = int(t_end / period)
        for k in range(n + 1):
            t = round(k * period, 6)
            nav, armed = self.at(t, start)
            out.append(VehicleStatus(t=t, vehicle=vehicle, nav_state=nav, armed=armed))
        return out


# ----------------------------------------------------------------------------- px4_ros_com


def px4_ros_com(
    duration: float = 60.0,
    *,
    jitter_s: float = 0.001,
    position: tuple[float, float, float] = (0.0, 0.0, -5.0),
    stall: tuple[float, float] | None = None,
) -> list[Event]:
    """``offboard_control``: the 100 ms timer runs a millisecond late now and then (``jitter_s``);
    ``stall`` (start, end) silences the node (a hazard variant)."""
    vehicle = Vehicle(LOITER)
    events: list[Event] = []
    n = int(duration / 0.1)
    for k in range(n + 1):
        t = round(0.1 * k + (jitter_s if k % 4 == 0 else 0.0), 6)
        if stall is not None and stall[0] <= t < stall[1]:
            continue
        if k == 10:
            events.append(Command(t=t, command=DO_SET_MODE, params=OFFBOARD_MODE))
            events.append(Command(t=round(t + 0.0001, 6), command=ARM_DISARM, params=ARM))
            events.append(CommandAck(t=round(t + 0.004, 6), command=DO_SET_MODE, result=0))
            events.append(CommandAck(t=round(t + 0.009, 6), command=ARM_DISARM, result=0))
            vehicle.set(t + 0.004, nav=OFFBOARD)
            vehicle.set(t + 0.009, armed=True)
        stamp = EPOCH_US + round(t * 1e6)
        t_ocm, t_sp = round(t + 0.0002, 6), round(t + 0.0003, 6)
        events.append(ControlMode(t=t_ocm, position=True, sender_time_us=stamp))
        events.append(
            TrajectorySetpoint(t=t_sp, position=position, yaw=-3.14, sender_time_us=stamp)
        )
    events += vehicle.statuses((LOITER, False), duration, 0.5)
    return sorted(events, key=lambda e: e.t)


# ----------------------------------------------------------------------------- MAVSDK


Setpoint = Callable[[float], Event]

VEL_NED_MASK = 1 | 2 | 4 | 64 | 128 | 256 | 2048
VEL_BODY_MASK = 1 | 2 | 4 | 64 | 128 | 256 | 1024
GLOBAL_MASK = 8 | 16 | 32 | 64 | 128 | 256 | 2048
ATTITUDE_MASK = 1 | 2 | 4


def velocity_ned(
    vx: float = 0.0, vy: float = 0.0, vz: float = 0.0, yaw_deg: float = 0.0
) -> Setpoint:
    def make(t: float) -> Event:
        return SetPositionTargetLocal(
            t=t,
            vehicle="1",
            target_system=1,
            target_component=1,
            coordinate_frame=1,
            type_mask=VEL_NED_MASK,
            velocity=(vx, vy, vz),
            yaw=math.radians(yaw_deg),
        )

    return make


def velocity_body(
    forward: float = 0.0, right: float = 0.0, down: float = 0.0, yawspeed_deg: float = 0.0
) -> Setpoint:
    def make(t: float) -> Event:
        return SetPositionTargetLocal(
            t=t,
            vehicle="1",
            target_system=1,
            target_component=1,
            coordinate_frame=8,
            type_mask=VEL_BODY_MASK,
            velocity=(forward, right, down),
            yaw_rate=math.radians(yawspeed_deg),
        )

    return make


def position_global(lat: float, lon: float, alt: float, yaw_deg: float, frame: int = 6) -> Setpoint:
    def make(t: float) -> Event:
        return SetPositionTargetGlobal(
            t=t,
            vehicle="1",
            target_system=1,
            target_component=1,
            coordinate_frame=frame,
            type_mask=GLOBAL_MASK,
            lat_int=int(lat * 1e7),
            lon_int=int(lon * 1e7),
            alt=alt,
            yaw=math.radians(yaw_deg),
        )

    return make


def attitude(roll_deg: float, thrust: float) -> Setpoint:
    roll = math.radians(roll_deg)
    q = (math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0)

    def make(t: float) -> Event:
        return SetAttitudeTarget(
            t=t,
            vehicle="1",
            target_system=1,
            target_component=1,
            type_mask=ATTITUDE_MASK,
            q=q,
            thrust=thrust,
        )

    return make


class Mavsdk:
    """MAVSDK's Offboard and Action plugins against a PX4 that answers as the gate spec says;
    ``t`` moves as the example's calls and sleeps do."""

    def __init__(self, px4: str) -> None:
        self.px4 = px4
        self.t = 0.0
        self.events: list[Event] = []
        self.vehicle = Vehicle(LOITER)
        self.current: Setpoint | None = None
        self.next_send = 0.0

    def _at(self, dt: float = 0.0) -> float:
        return round(self.t + dt, 6)

    def _command(self, command: int, params: tuple[float, ...], answer_nav: int | None) -> None:
        sent = self._at(0.001)
        full = (tuple(params) + (0.0,) * 7)[:7]
        self.events.append(
            Command(t=sent, vehicle="1", command=command, params=full, target_system=1)  # type: ignore[arg-type]
        )
        acks = [0.02, 0.026] if command == DO_SET_MODE and double_ack(self.px4) else [0.02]
        for dt in acks:
            self.events.append(CommandAck(t=self._at(dt), vehicle="1", command=command, result=0))
        if answer_nav is not None:
            self.vehicle.set(self.t + acks[-1], nav=answer_nav)
        self.sleep(0.03)  # the call returns with the (last) ack

    def sleep(self, seconds: float) -> None:
        end = self.t + seconds
        while self.current is not None and self.next_send < end - 1e-9:
            self.events.append(self.current(round(self.next_send, 6)))
            self.next_send += 0.05
        self.t = end

    def set(self, setpoint: Setpoint) -> None:
        self.current = setpoint
        self.events.append(setpoint(self._at()))
        self.next_send = self.t + 0.05  # reset_call_every
        self.t += 0.0005

    def start(self) -> None:
        self._command(DO_SET_MODE, OFFBOARD_MODE, OFFBOARD)

    def stop(self) -> None:
        self.current = None
        self._command(DO_SET_MODE, HOLD_MODE, LOITER)

    def arm(self) -> None:
        self._command(ARM_DISARM, ARM, None)
        self.vehicle.set(self.t, armed=True)

    def takeoff(self, climb_s: float = 8.0) -> None:
        self._command(NAV_TAKEOFF, (0.0,) * 7, TAKEOFF)
        self.vehicle.set(self.t + climb_s, nav=LOITER)

    def land(self, descent_s: float = 12.0) -> None:
        self._command(NAV_LAND, (0.0,) * 7, LAND)
        self.vehicle.set(self.t + descent_s, armed=False)

    def recording(self) -> list[Event]:
        events = self.events + self.vehicle.statuses((LOITER, False), self.t, 1.0, "1")
        return sorted(events, key=lambda e: e.t)


def mavsdk_offboard_example(px4: str) -> list[Event]:
    """MAVSDK ``examples/offboard/offboard.cpp``, section by section."""
    s = Mavsdk(px4)
    s.sleep(3.0)  # waiting for health_all_ok
    s.arm()
    s.takeoff()
    s.sleep(10.0)  # in_air_future.wait_for(seconds(10))
    lat, lon = 47.3977419, 8.5455938
    # offb_ctrl_pos_global
    s.set(position_global(lat + 0.0001, lon, 20.0, 0.0))
    s.start()
    s.sleep(10.0)
    s.set(position_global(lat + 0.0001, lon + 0.0001, 15.0, 90.0))
    s.sleep(10.0)
    s.set(position_global(lat, lon, 498.0, 180.0, frame=5))
    s.sleep(10.0)
    s.stop()
    # offb_ctrl_attitude
    s.set(attitude(30.0, 0.6))
    s.start()
    for roll, seconds in ((30.0, 2.0), (0.0, 1.0), (-30.0, 2.0), (0.0, 2.0)):
        s.set(attitude(roll, 0.6))
        s.sleep(seconds)
    s.stop()
    # offb_ctrl_ned
    s.set(velocity_ned())
    s.start()
    s.set(velocity_ned(yaw_deg=90.0))
    s.sleep(1.0)
    for i in range(2 * int(2 * math.pi / 0.01)):
        s.set(velocity_ned(vx=5.0 * math.sin(i * 0.01), yaw_deg=90.0))
        s.sleep(0.01)
    s.set(velocity_ned(yaw_deg=270.0))
    s.sleep(2.0)
    s.set(velocity_ned(vz=-2.0, yaw_deg=180.0))
    s.sleep(4.0)
    s.set(velocity_ned())  # "down_and_north" is sent all zeros (the example sets another struct)
    s.sleep(4.0)
    s.stop()
    # offb_ctrl_body
    s.set(velocity_body())
    s.start()
    for setpoint, seconds in (
        (velocity_body(down=-1.0, yawspeed_deg=60.0), 5.0),
        (velocity_body(down=-1.0, yawspeed_deg=-60.0), 5.0),
        (velocity_body(), 2.0),
        (velocity_body(forward=5.0, yawspeed_deg=30.0), 15.0),
        (velocity_body(), 5.0),
        (velocity_body(forward=5.0, right=-5.0, yawspeed_deg=30.0), 15.0),
        (velocity_body(), 8.0),
    ):
        s.set(setpoint)
        s.sleep(seconds)
    s.stop()
    s.land()
    s.sleep(15.0)
    return s.recording()


def takeoff_then_offboard(
    px4: str, *segments: tuple[Setpoint, float], takeoff: bool = True
) -> list[Event]:
    """Arm, an auto takeoff (or none), then offboard flying ``segments`` (setpoint, seconds),
    each re-sent at 20 Hz as MAVSDK does, then ``stop()``."""
    s = Mavsdk(px4)
    s.sleep(2.0)
    s.arm()
    if takeoff:
        s.takeoff()
        s.sleep(10.0)
    s.set(segments[0][0])
    s.start()
    for setpoint, seconds in segments:
        s.set(setpoint)
        s.sleep(seconds)
    s.stop()
    s.sleep(3.0)
    return s.recording()


# ----------------------------------------------------------------------------- MAVROS


def mavros_offb_node(duration: float = 60.0) -> list[Event]:
    """``offb_node.cpp`` (PX4 user guide, MAVROS example): ``/mavros/setpoint_position/local``
    at 20 Hz as MAVROS sends it (ENU (0, 0, 2) -> NED (0, 0, -2), yaw 0 ENU -> pi/2 NED), and
    ``/mavros/state``, which MAVROS publishes from the 1 Hz HEARTBEAT."""
    vehicle = Vehicle(POSCTL)
    events: list[Event] = []
    n = int(duration / 0.05)
    last_request = 0.0
    offboard = armed = False
    for k in range(n + 1):
        t = round(0.05 * k, 6)
        if k >= 100:
            if not offboard and t - last_request > 5.0:
                offboard, last_request = True, t
                vehicle.set(t + 0.02, nav=OFFBOARD)
            elif offboard and not armed and t - last_request > 5.0:
                armed, last_request = True, t
                vehicle.set(t + 0.02, armed=True)
        events.append(
            SetPositionTargetLocal(
                t=t,
                coordinate_frame=1,
                type_mask=0x9F8,
                position=(0.0, 0.0, -2.0),
                yaw=math.pi / 2,
            )
        )
    events += vehicle.statuses((POSCTL, False), duration, 1.0)
    return sorted(events, key=lambda e: e.t)


# ----------------------------------------------------------------------------- px4-ros2


def px4_ros2_goto(duration: float = 30.0) -> list[Event]:
    """An external mode of px4-ros2-interface-lib: PX4 runs it (EXTERNAL1) from 2 s, the mode
    publishes a TrajectorySetpoint towards its goal at 50 Hz while active; no OCM."""
    vehicle = Vehicle(LOITER, armed=True)
    vehicle.set(2.0, nav=EXTERNAL1)
    events: list[Event] = []
    for k in range(1, int((duration - 2.0) / 0.02)):
        t = round(2.0 + 0.02 * k, 6)
        x = min(10.0, 0.5 * (t - 2.0))
        events.append(TrajectorySetpoint(t=t, position=(x, 0.0, -5.0), yaw=0.0))
    events += vehicle.statuses((LOITER, True), duration, 0.5)
    return sorted(events, key=lambda e: e.t)
