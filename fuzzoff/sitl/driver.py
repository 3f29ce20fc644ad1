"""What a scenario program does to PX4, step by step, on PX4's clock.

A ``Driver`` wraps a ``Link``: it streams setpoints at a rate for a time measured on PX4's
clock (``stream``), sends the odd joystick sample beside them when the scenario has manual
control, switches modes and arms, and notes every step with PX4's time (``steps``), so that a
run can say what it did and when.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.mavlink_ids import (
    MAV_CMD_COMPONENT_ARM_DISARM,
    MAV_CMD_DO_VTOL_TRANSITION,
    MAV_FRAME_LOCAL_NED,
    MAV_VTOL_STATE_FW,
    MAV_VTOL_STATE_MC,
)
from fuzzoff.sitl.link import Ack, Link, LinkError

POSITION = 0x0DF8
"""type_mask: position only (velocity, acceleration, yaw and yaw rate ignored)."""
VELOCITY = 0x0DC7
"""type_mask: velocity only."""
ACCELERATION = 0x0C3F
"""type_mask: acceleration only (FORCE bit clear)."""
ATTITUDE_AND_THRUST = 0b00000111
"""SET_ATTITUDE_TARGET type_mask: the attitude and the thrust, body rates ignored."""
ATTITUDE_NO_THRUST = 0b01000111
"""SET_ATTITUDE_TARGET type_mask: the attitude only, body rates and thrust ignored (bit 64)."""
FORCE_DISARM = 21196.0
"""``param2`` of MAV_CMD_COMPONENT_ARM_DISARM that makes PX4 disarm in the air too."""
NAV_POSCTL, NAV_LOITER, NAV_RTL, NAV_OFFBOARD, NAV_TAKEOFF, NAV_LAND = 2, 4, 5, 14, 17, 18
MANUAL_EVERY_S = 0.1
"""A MAVLink joystick at 10 Hz: PX4 declares manual control lost after COM_RC_LOSS_T (0.5 s)."""

Setpoint = Callable[["Driver"], None]


@dataclass(slots=True)
class Step:
    px4_t: float
    what: str
    result: int | None = None


@dataclass(slots=True)
class Driver:
    link: Link
    manual: bool = False
    steps: list[Step] = field(default_factory=list)
    pitch_stick: float = 0.0
    """Where the joystick's pitch stick is (-1..1): what every joystick sample sends."""
    _next_manual: float = 0.0

    def now(self) -> float:
        return self.link.clock.now()

    def note(self, what: str, ack: Ack | None = None) -> Ack | None:
        self.steps.append(Step(self.now(), what, None if ack is None else ack.result))
        return ack

    def tick(self) -> None:
        """Send a joystick sample when one is due (a scenario with manual control)."""
        if self.manual and self.now() >= self._next_manual:
            self.link.manual_control(x=round(self.pitch_stick * 1000))
            self._next_manual = self.now() + MANUAL_EVERY_S

    def wait(self, seconds: float) -> None:
        """Send nothing but the joystick (if any) for ``seconds`` of PX4's time."""
        self.link.sleep_until(self.now() + seconds, self.tick)

    def stream(self, setpoint: Setpoint, seconds: float, hz: float = 10.0) -> None:
        """Send ``setpoint`` at ``hz`` for ``seconds`` of PX4's time."""
        start = self.now()
        n = max(1, round(seconds * hz))
        for i in range(n):
            setpoint(self)
            self.tick()
            self.link.sleep_until(start + (i + 1) / hz, self.tick)

    def move_pitch_stick(
        self, setpoint: Setpoint, to: float, seconds: float, hz: float = 20.0
    ) -> None:
        """Move the joystick's pitch stick steadily to ``to`` over ``seconds`` (a sample at
        ``hz``), the setpoint stream going on at 10 Hz: the way a pilot's stick moves, and the
        way PX4 1.18's ``sticks_moving`` needs (a steady ramp, not a step)."""
        start, begin = self.now(), self.pitch_stick
        n = max(1, round(seconds * hz))
        every = max(1, round(hz / 10.0))
        for i in range(1, n + 1):
            self.pitch_stick = begin + (to - begin) * i / n
            self.link.manual_control(x=round(self.pitch_stick * 1000))
            if i % every == 0:
                setpoint(self)
            self.link.sleep_until(start + i / hz)
        self._next_manual = self.now() + MANUAL_EVERY_S

    def position(self, x: float, y: float, z: float, frame: int = MAV_FRAME_LOCAL_NED) -> Setpoint:
        def send(d: Driver) -> None:
            d.link.position_target(frame=frame, type_mask=POSITION, pos=(x, y, z))

        return send

    def velocity(self, vx: float, vy: float, vz: float) -> Setpoint:
        def send(d: Driver) -> None:
            d.link.position_target(type_mask=VELOCITY, vel=(vx, vy, vz))

        return send

    def acceleration(self, ax: float, ay: float, az: float) -> Setpoint:
        def send(d: Driver) -> None:
            d.link.position_target(type_mask=ACCELERATION, acc=(ax, ay, az))

        return send

    def attitude(self, thrust: float, type_mask: int = ATTITUDE_AND_THRUST) -> Setpoint:
        def send(d: Driver) -> None:
            d.link.attitude_target((1.0, 0.0, 0.0, 0.0), thrust, type_mask)

        return send

    def set_mode(
        self, nav_state: int, label: str, target: tuple[int, int] | None = None
    ) -> Ack | None:
        """DO_SET_MODE to the autopilot, or to ``target`` (system, component) as a client that
        addresses it wrongly would (sent once: PX4 may answer nothing)."""
        to = "" if target is None else f" addressed to {target[0]}/{target[1]}"
        return self.note(f"switch to {label}{to}", self.link.set_mode(nav_state, target))

    def set_custom_mode(self, main: int, sub: int, label: str) -> Ack | None:
        """DO_SET_MODE with this main and sub mode as sent, whether PX4 has the mode or not."""
        return self.note(
            f"switch to {label} (main {main}, sub {sub})", self.link.set_custom_mode(main, sub)
        )

    def transition(self, to_fw: bool) -> Ack | None:
        """DO_VTOL_TRANSITION to fixed-wing (or back to multicopter) flight."""
        state = MAV_VTOL_STATE_FW if to_fw else MAV_VTOL_STATE_MC
        ack = self.link.command(MAV_CMD_DO_VTOL_TRANSITION, state)
        return self.note(f"VTOL transition to {'FW' if to_fw else 'MC'}", ack)

    def arm(self) -> Ack | None:
        return self.note("arm", self.link.arm(True))

    def disarm(self) -> Ack | None:
        return self.note("disarm", self.link.arm(False))

    def force_disarm(self) -> Ack | None:
        """A disarm PX4 takes in the air too (param2 21196): an airplane rolling on the ground
        counts as flying, and a plain disarm is refused."""
        ack = self.link.command(MAV_CMD_COMPONENT_ARM_DISARM, 0.0, FORCE_DISARM)
        return self.note("disarm (forced)", ack)

    def land_and_wait(self, timeout: float = 40.0) -> None:
        """AUTO_LAND, then wait (joystick going) until PX4 disarms by itself after landing."""
        self.set_mode(NAV_LAND, "AUTO_LAND")
        deadline = self.now() + timeout
        while self.link.view.armed and self.now() < deadline:
            self.wait(0.5)
        self.note("disarmed" if not self.link.view.armed else "still armed after landing")

    def require(self, ack: Ack | None, what: str) -> None:
        """Stop the scenario when a step it depends on failed."""
        if ack is None or ack.result != 0:
            got = "no ack" if ack is None else f"ack {ack.result}"
            raise LinkError(f"{what}: PX4 refused ({got}); cannot bring the vehicle there")
