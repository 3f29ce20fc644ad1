"""Scenario programs: what a companion computer does to PX4, one short flight each.

Each starts on a landed, disarmed vehicle that passed its pre-arm checks, in the mode PX4 chose
at boot, and ends landed and disarmed where it can. ``kind`` says whether the program is a
*clean* use of offboard (fuzzoff should find nothing at warning or above in its recordings) or
holds a *hazard* (``hazard`` names the error code fuzzoff should give, and why).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import field
from typing import Literal

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.mavlink_ids import MAV_FRAME_LOCAL_ENU
from fuzzoff.sitl.airframes import (  # fw_gate: each build's thrust
    AIRFRAMES,
    AIRPLANE_OUTPUTS,
    on_release,
)
from fuzzoff.sitl.driver import (
    ATTITUDE_NO_THRUST,
    NAV_LOITER,
    NAV_OFFBOARD,
    NAV_TAKEOFF,
    Driver,
    Setpoint,
)
from fuzzoff.sitl.link import LinkError

ALT = -2.5
"""Cruise height, NED (2.5 m up)."""


@dataclass(frozen=True, slots=True)
class Scenario:
    name: str
    summary: str
    program: Callable[[Driver], None]
    kind: Literal["clean", "hazard"]
    hazard: str | None = None
    """What the hazard is, for the user."""
    codes: tuple[str, ...] = ()
    """The error codes that name the hazard (any one of them at error: a tlog and a ULog hold
    different parts of it, e.g. the dropped ENU messages only reach the tlog)."""
    manual: bool = False
    """Send a centred MAVLink joystick at 10 Hz throughout (manual control present)."""
    params: dict[str, float] = field(default_factory=dict)
    shown_in: tuple[str, ...] = (".tlog", ".ulg")
    """The recordings that can show the hazard: a ULog holds no command PX4's receiver dropped."""
    hazard_until: tuple[int, int] | None = None
    """The first PX4 release (major, minor) that does what the program means: there the run is
    context (a client relying on that release), not a hazard."""
    vehicle: str = "quad"
    """The SIH airframe it flies (``fuzzoff.sitl.airframes``; ``sitl run --vehicle`` overrides)."""
    flies_on: tuple[str, ...] | None = None
    """The bundles whose PX4 can fly the program (None: every bundle with the airframe)."""
    params_on: dict[str, dict[str, float]] = field(default_factory=dict)
    """More ``params`` on the bundles whose name starts with the key (``params_for``)."""

    def params_for(self, release: str) -> dict[str, float]:
        """The parameters the run sets on the bundle ``release``."""
        return on_release(self.params, self.params_on, release)


def _offboard_takeoff(d: Driver, z: float = ALT, climb_s: float = 6.0) -> None:
    """Stream a hover setpoint, switch to OFFBOARD, arm, climb: the documented sequence."""
    d.stream(d.position(0, 0, z), 1.5)
    d.require(d.set_mode(NAV_OFFBOARD, "OFFBOARD"), "switch to OFFBOARD")
    d.stream(d.position(0, 0, z), 0.5)
    d.require(d.arm(), "arm in OFFBOARD")
    d.stream(d.position(0, 0, z), climb_s)


def _auto_takeoff(d: Driver) -> None:
    d.require(d.set_mode(NAV_TAKEOFF, "AUTO_TAKEOFF"), "switch to AUTO_TAKEOFF")
    d.require(d.arm(), "arm in AUTO_TAKEOFF")
    d.wait(9.0)


def clean_offboard(d: Driver) -> None:
    _offboard_takeoff(d)
    d.stream(d.position(3, 0, ALT), 5.0)
    d.stream(d.position(0, 0, ALT), 4.0)
    d.land_and_wait()


def stream_loss(d: Driver) -> None:
    _offboard_takeoff(d)
    d.note("stream stops")
    d.wait(3.0)
    d.note("stream resumes")
    d.stream(d.position(0, 0, ALT), 5.0)
    d.land_and_wait()


def stall_1_5s(d: Driver) -> None:
    _offboard_takeoff(d)
    d.note("loop stalls")
    d.wait(1.5)
    d.note("loop back")
    d.stream(d.position(0, 0, ALT), 4.0)
    d.land_and_wait()


def disarmed_switch_no_stream(d: Driver) -> None:
    d.wait(1.0)
    d.set_mode(NAV_OFFBOARD, "OFFBOARD")
    d.wait(1.0)
    d.arm()
    d.wait(2.0)
    d.set_mode(NAV_LOITER, "AUTO_LOITER")
    d.wait(1.0)


def switch_no_stream_flying(d: Driver) -> None:
    _auto_takeoff(d)
    d.set_mode(NAV_OFFBOARD, "OFFBOARD")
    d.wait(2.0)
    d.land_and_wait()


def disarm_in_flight(d: Driver) -> None:
    _offboard_takeoff(d)
    d.disarm()
    d.stream(d.position(0, 0, ALT), 3.0)
    d.land_and_wait()


def acceleration_only(d: Driver) -> None:
    d.stream(d.acceleration(0, 0, 0), 1.5)
    d.require(d.set_mode(NAV_OFFBOARD, "OFFBOARD"), "switch to OFFBOARD")
    d.stream(d.acceleration(0, 0, 0), 0.5)
    d.require(d.arm(), "arm in OFFBOARD")
    d.stream(d.acceleration(0, 0, -1.0), 1.5)
    d.stream(d.acceleration(0, 0, 1.0), 1.5)
    d.stream(d.acceleration(0, 0, 0), 2.0)
    d.land_and_wait()


def attitude(d: Driver) -> None:
    d.stream(d.attitude(0.3), 1.5)
    d.require(d.set_mode(NAV_OFFBOARD, "OFFBOARD"), "switch to OFFBOARD")
    d.stream(d.attitude(0.3), 0.5)
    d.require(d.arm(), "arm in OFFBOARD")
    d.stream(d.attitude(0.3), 4.0)
    d.land_and_wait()


def attitude_no_thrust(d: Driver) -> None:
    """SET_ATTITUDE_TARGET level with the thrust ignored (type_mask bit 64), from the ground:
    PX4 up to 1.17 takes it as a keep-alive (the switch and the arm are accepted, thrust 0
    keeps the vehicle on the ground); 1.18 and main drop it, keep-alive included (the switch
    is accepted disarmed, the arm refused)."""
    setpoint = d.attitude(0.5, ATTITUDE_NO_THRUST)
    d.stream(setpoint, 1.5)
    d.set_mode(NAV_OFFBOARD, "OFFBOARD")
    d.stream(setpoint, 0.5)
    d.arm()
    d.stream(setpoint, 2.0)
    if d.link.view.armed:
        d.disarm()
    d.wait(1.0)


def enu_frame(d: Driver) -> None:
    _auto_takeoff(d)
    d.stream(d.position(0, 0, -ALT, frame=MAV_FRAME_LOCAL_ENU), 2.0)
    d.set_mode(NAV_OFFBOARD, "OFFBOARD")
    d.stream(d.position(0, 0, -ALT, frame=MAV_FRAME_LOCAL_ENU), 2.0)
    d.land_and_wait()


def enu_z_from_ground(d: Driver) -> None:
    """A program that thinks in ENU sends z = +2.5 (up) in LOCAL_NED: 2.5 m below ground."""
    d.stream(d.position(0, 0, -ALT), 1.5)
    d.set_mode(NAV_OFFBOARD, "OFFBOARD")
    d.stream(d.position(0, 0, -ALT), 0.5)
    d.arm()
    d.stream(d.position(0, 0, -ALT), 5.0)
    d.land_and_wait()


def enu_z_airborne(d: Driver) -> None:
    _offboard_takeoff(d)
    d.note("setpoint z flips to +2.5 (ENU thinking)")
    d.stream(d.position(0, 0, -ALT), 5.0)
    d.land_and_wait()


def one_setpoint_then_switch(d: Driver) -> None:
    d.stream(d.position(0, 0, ALT), 0.1)
    d.require(d.set_mode(NAV_OFFBOARD, "OFFBOARD"), "switch to OFFBOARD")
    d.require(d.arm(), "arm in OFFBOARD")
    d.stream(d.position(0, 0, ALT), 6.0)
    d.land_and_wait()


def frozen_velocity(d: Driver) -> None:
    _offboard_takeoff(d)
    d.note("velocity 2 m/s frozen")
    d.stream(d.velocity(2.0, 0, 0), 20.0)
    d.stream(d.velocity(0, 0, 0), 2.0)
    d.land_and_wait()


def switch_to_broadcast(d: Driver) -> None:
    """The documented sequence, but the switch goes to system 0, component 0 (a script that
    sends before it has heard PX4's HEARTBEAT): only 1.18 and later take it."""
    d.stream(d.position(0, 0, ALT), 1.5)
    d.set_mode(NAV_OFFBOARD, "OFFBOARD", target=(0, 0))
    d.stream(d.position(0, 0, ALT), 0.5)
    ack = d.arm()
    if ack is None or ack.result != 0:
        d.stream(d.position(0, 0, ALT), 1.0)
        return
    d.stream(d.position(0, 0, ALT), 5.0)
    d.land_and_wait()


def hold_with_unknown_sub_mode(d: Driver) -> None:
    """Offboard flight, then a "hold" sent as AUTO with sub-mode 42, which no PX4 has: the
    vehicle stays in OFFBOARD (1.16 and 1.17 first ack it ACCEPTED), the stream goes on."""
    _offboard_takeoff(d)
    d.set_custom_mode(4, 42, "a hold that does not exist")
    d.stream(d.position(0, 0, ALT), 3.0)
    d.land_and_wait()


VTOL_MC_ALT = -20.0
"""A standard VTOL climbs this high in MC before the transition (NED)."""
VTOL_FW_POINT = (400.0, 0.0, -30.0)
"""Where it flies in FW: far enough that it is still on its way when the run ends."""
VTOL_FW_S = 15.0


VTOL_FW_FLIES_ON = (
    "1.17.0",
    "1.17.0-ros2-rover",
    "1.18.0-alpha1",
    "1.18.0-beta1-head",
    "main-2026-08-13",
)
"""Where the standard VTOL reaches FW flight: on 1.16.2 its transition ends back in MC (the
pusher did not move it, PX4 quad-chuted 6.4-6.6 s in; docs/sitl.md), so the programs about FW
flight fly there in MC only."""


def _vtol_to_fw(d: Driver) -> None:
    """MC offboard takeoff to 20 m, then DO_VTOL_TRANSITION to FW while in OFFBOARD, streaming
    a full position setpoint (x, y and z: a NaN z glides on 1.18, ``vtol_fw_glide``)."""
    _offboard_takeoff(d, VTOL_MC_ALT, climb_s=10.0)
    d.stream(d.position(0, 0, VTOL_MC_ALT), 0.5)
    d.require(d.transition(to_fw=True), "DO_VTOL_TRANSITION to FW")
    d.stream(d.position(*VTOL_FW_POINT), VTOL_FW_S)


def _vtol_back_and_land(d: Driver) -> None:
    d.transition(to_fw=False)
    d.stream(d.position(*VTOL_FW_POINT), 6.0)
    d.land_and_wait(60.0)


def vtol_offboard(d: Driver) -> None:
    _vtol_to_fw(d)
    _vtol_back_and_land(d)


def vtol_loss(d: Driver) -> None:
    """A 2 s stream stop in each phase: hovering in MC, then cruising in FW."""
    _offboard_takeoff(d, VTOL_MC_ALT, climb_s=10.0)
    d.note("stream stops (MC)")
    d.wait(2.0)
    d.note("stream resumes (MC)")
    d.stream(d.position(0, 0, VTOL_MC_ALT), 3.0)
    d.require(d.transition(to_fw=True), "DO_VTOL_TRANSITION to FW")
    d.stream(d.position(*VTOL_FW_POINT), 10.0)
    d.note("stream stops (FW)")
    d.wait(2.0)
    d.note("stream resumes (FW)")
    d.stream(d.position(*VTOL_FW_POINT), 4.0)
    _vtol_back_and_land(d)


def vtol_fw_glide(d: Driver) -> None:
    """In FW flight, position setpoints with z NaN: 1.18 takes a fixed-wing's setpoint by
    component and glides (throttle off) on a NaN altitude; then the full setpoint again."""
    _vtol_to_fw(d)
    x, y, _ = VTOL_FW_POINT
    d.note("z NaN: glide")
    d.stream(d.position(x, y, math.nan), 8.0)
    d.note("z given again")
    d.stream(d.position(*VTOL_FW_POINT), 4.0)
    _vtol_back_and_land(d)


def _typed(mask: int, point: tuple[float, float, float]) -> Setpoint:
    """A LOCAL_NED position setpoint with ``type_mask`` as given (the fixed-wing setpoint types)."""

    def send(d: Driver) -> None:
        d.link.position_target(type_mask=mask, pos=point)

    return send


FW_SETPOINT_TYPES = ((12288, "loiter"), (292, "glide"), (8192, "land"), (16384, "idle"))
"""The fixed-wing setpoint types of PX4's offboard docs, in the order flown (takeoff, 4096, is
left out: it is sent in flight here, and would take a runway)."""


def vtol_fw_types(d: Driver) -> None:
    """In FW flight, the fixed-wing setpoint types of the docs, 4 s each, then the plain
    position setpoint again: how each release takes them (1.13-1.17 do not read the type bits;
    1.18 takes the setpoint by component)."""
    _vtol_to_fw(d)
    for mask, label in FW_SETPOINT_TYPES:
        d.note(f"type_mask {mask} ({label})")
        d.stream(_typed(mask, VTOL_FW_POINT), 4.0)
    d.note("position setpoint again")
    d.stream(d.position(*VTOL_FW_POINT), 4.0)
    _vtol_back_and_land(d)


FW_TAKEOFF_TYPE = 4096
"""The docs' takeoff setpoint type (``type_mask`` 0x1000, every ignore bit clear)."""


def vtol_fw_takeoff_type(d: Driver) -> None:
    """In FW flight, the takeoff setpoint type (4096) at the cruise point for 6 s, then the
    plain position setpoint again: does PX4 read it as a takeoff (a climb, full throttle) or
    take the position?"""
    _vtol_to_fw(d)
    d.note(f"type_mask {FW_TAKEOFF_TYPE} (takeoff)")
    d.stream(_typed(FW_TAKEOFF_TYPE, VTOL_FW_POINT), 6.0)
    d.note("position setpoint again")
    d.stream(d.position(*VTOL_FW_POINT), 4.0)
    _vtol_back_and_land(d)


VTOL_FW_VELOCITY = (0.0, 10.0, 0.0)
"""10 m/s east (NED), the velocity-only setpoint flown in FW."""


def vtol_fw_velocity(d: Driver) -> None:
    """In FW flight, a velocity-only setpoint (10 m/s east) for 8 s, then the position setpoint
    again: the docs say fixed-wing takes the position only (OFB604)."""
    _vtol_to_fw(d)
    d.note("velocity only: 10 m/s east")
    d.stream(d.velocity(*VTOL_FW_VELOCITY), 8.0)
    d.note("position setpoint again")
    d.stream(d.position(*VTOL_FW_POINT), 4.0)
    _vtol_back_and_land(d)


TAILSITTER_PARAMS = AIRFRAMES["tailsitter"].fixes
"""The tailsitter's airspeed use and right elevon (``airframes.TAILSITTER_FIXES``)."""

TAILSITTER_FLIES_ON: tuple[str, ...] | None = None
"""Every bundle (with the parameters above)."""

AIRPLANE_FLIES_ON = (
    "1.14.4",
    "1.15.4",
    "1.16.2",
    "1.17.0",
    "1.18.0-alpha1",
    "1.18.0-beta1-head",
    "main-2026-08-13",
)
"""Where SIH's airplane takes off by itself: every bundle, with ``AIRPLANE_PARAMS`` (docs/sitl.md:
on 1.18 only with the 6 N ``SIH_F_T_MAX``; on 1.14 and 1.15 only with ``AIRPLANE_PARAMS_ON``)."""

AIRPLANE_PARAMS = AIRFRAMES["fw"].fixes
"""The airplane's outputs where SIH reads them and its 6 N thrust (``airframes.AIRPLANE_OUTPUTS``,
``airframes.AIRPLANE_THRUST``); on 1.14 and 1.15 also ``AIRPLANE_PARAMS_ON``."""
AIRPLANE_PARAMS_ON = AIRFRAMES["fw"].fixes_on
"""1.14's and 1.15's elevator sign, level lift-off and the 1.16 airframe's aileron and gains
(``airframes.AIRPLANE_1_14``)."""

FW_CLIMB_TO_M = 15.0
"""The airplane's runway takeoff (AUTO_TAKEOFF) climbs at least this high before the switch."""
FW_TAKEOFF_S = 30.0
"""How long the runway takeoff may take, from the arm to Hold at the takeoff altitude (25 m):
10-15 s of PX4's time on 1.16.2 to main."""
FW_POINT = (400.0, 0.0, -30.0)


def _fw_takeoff(d: Driver) -> None:
    """AUTO_TAKEOFF (the SIH airplane's runway takeoff, RWTO_TKOFF 1) until PX4 ends it in Hold,
    at least 15 m up, then the stream and the switch to OFFBOARD in the air. Switching while
    the takeoff ends races it: on main a switch 0.14 s before Hold was acknowledged and never
    flown (the navigator's Hold came after it, ``fw_loss`` 2026-12-03, not kept)."""
    d.require(d.set_mode(NAV_TAKEOFF, "AUTO_TAKEOFF"), "switch to AUTO_TAKEOFF")
    d.require(d.arm(), "arm in AUTO_TAKEOFF")
    # HEARTBEAT (1 Hz) shows the arm up to a second after its ack: judge a disarm after that
    d.link.wait_for(lambda v: bool(v.armed), 2.0)
    deadline = d.now() + FW_TAKEOFF_S

    def climbing() -> bool:
        view = d.link.view
        return (view.relative_alt_m or 0.0) < FW_CLIMB_TO_M or view.nav_state == NAV_TAKEOFF

    while climbing() and d.now() < deadline:
        d.wait(0.5)
        if not d.link.view.armed:
            # 1.14.4/1.15.4: "Attitude failure (roll)" at rotation, disarmed by failsafe; the
            # estimate of the tumbling airframe may still read 15 m
            raise LinkError("PX4 disarmed the airplane during its takeoff")
    if climbing():
        raise LinkError(
            f"the airplane did not end its takeoff {FW_CLIMB_TO_M:g} m up in {FW_TAKEOFF_S:g} s"
        )
    d.note("takeoff done (Hold)")
    d.stream(d.position(*FW_POINT), 1.5)
    d.require(d.set_mode(NAV_OFFBOARD, "OFFBOARD"), "switch to OFFBOARD")


def _fw_hold(d: Driver) -> None:
    d.set_mode(NAV_LOITER, "AUTO_LOITER")
    d.wait(1.0)


def fw_offboard(d: Driver) -> None:
    _fw_takeoff(d)
    d.stream(d.position(*FW_POINT), 10.0)
    _fw_hold(d)


def fw_loss(d: Driver) -> None:
    _fw_takeoff(d)
    d.stream(d.position(*FW_POINT), 4.0)
    d.note("stream stops")
    d.wait(3.0)
    d.note("stream resumes")
    d.stream(d.position(*FW_POINT), 4.0)
    _fw_hold(d)


FW_GROUND_POINT = (0.0, 0.0, 0.0)
"""Where the airplane's ground gate run holds: where it stands, on the ground."""


def fw_gate(d: Driver) -> None:
    """The airplane's gate on the ground, for the builds where it cannot take off: a position
    stream, the switch to OFFBOARD and the arm, a 3 s stream stop (the loss and its action),
    the stream again, a disarm (forced when PX4 counts the rolling airplane as flying)."""
    d.stream(d.position(*FW_GROUND_POINT), 1.5)
    d.set_mode(NAV_OFFBOARD, "OFFBOARD")
    d.stream(d.position(*FW_GROUND_POINT), 0.5)
    d.arm()
    d.stream(d.position(*FW_GROUND_POINT), 3.0)
    d.note("stream stops")
    d.wait(3.0)
    d.note("stream resumes")
    d.stream(d.position(*FW_GROUND_POINT), 3.0)
    _fw_ground_end(d)


FW_TAKEOFF_TYPE_ON = ("1.16.2", "1.17.0", "1.18.0-beta1-head")
"""The bundles ``fw_takeoff_type`` was flown on."""

FW_TAKEOFF_POINT = (200.0, 0.0, -30.0)
"""Where the airplane's takeoff setpoint points: 200 m ahead (north, the way it faces), 30 m up."""


def _fw_ground_end(d: Driver) -> None:
    """A disarm, forced when PX4 counts the airplane as flying (``fw_gate``'s end)."""
    if d.link.view.armed:
        ack = d.disarm()
        if ack is None or ack.result != 0:
            d.force_disarm()
    d.wait(1.0)


def fw_takeoff_type(d: Driver) -> None:
    """The airplane on the ground: the takeoff setpoint type (4096) 200 m ahead and 30 m up,
    the switch to OFFBOARD, the arm, 15 s of the stream, a disarm (forced if PX4 counts it
    flying). Does PX4 run a runway takeoff in OFFBOARD, or take a plain position?"""
    takeoff = _typed(FW_TAKEOFF_TYPE, FW_TAKEOFF_POINT)
    d.stream(takeoff, 1.5)
    d.require(d.set_mode(NAV_OFFBOARD, "OFFBOARD"), "switch to OFFBOARD")
    d.stream(takeoff, 0.5)
    d.require(d.arm(), "arm in OFFBOARD")
    d.stream(takeoff, 15.0)
    _fw_ground_end(d)


def _rover_start(d: Driver) -> None:
    d.stream(d.position(0, 0, 0), 1.5)
    d.require(d.set_mode(NAV_OFFBOARD, "OFFBOARD"), "switch to OFFBOARD")
    d.stream(d.position(0, 0, 0), 0.5)
    d.require(d.arm(), "arm in OFFBOARD")


def _rover_stop(d: Driver) -> None:
    d.stream(d.velocity(0, 0, 0), 2.0)
    d.disarm()
    d.wait(0.5)


def rover_offboard(d: Driver) -> None:
    _rover_start(d)
    d.stream(d.position(10, 0, 0), 10.0)
    d.stream(d.velocity(1.0, 1.0, 0), 5.0)
    _rover_stop(d)


def rover_loss(d: Driver) -> None:
    _rover_start(d)
    d.stream(d.position(10, 0, 0), 6.0)
    d.note("stream stops")
    d.wait(3.0)
    d.note("stream resumes")
    d.stream(d.position(10, 0, 0), 4.0)
    _rover_stop(d)


def sticks_moved(d: Driver) -> None:
    """A pilot takes over an OFFBOARD hover: the pitch stick moves steadily to 0.6 in 0.3 s
    (2 per second) and back, the stream going on. 1.18 and main end OFFBOARD (Position, no
    return); 1.17 keeps it (COM_RC_OVERRIDE 1, auto modes only)."""
    _offboard_takeoff(d)
    d.note("pitch stick 0 -> 0.6 in 0.3 s and back")
    d.move_pitch_stick(d.position(0, 0, ALT), 0.6, 0.3)
    d.move_pitch_stick(d.position(0, 0, ALT), 0.0, 0.3)
    d.stream(d.position(0, 0, ALT), 4.0)
    d.land_and_wait()


SCENARIOS: dict[str, Scenario] = {
    s.name: s
    for s in (
        Scenario(
            "clean_offboard",
            "stream, switch, arm, climb to 2.5 m, fly 3 m and back, land",
            clean_offboard,
            "clean",
        ),
        Scenario(
            "loss_no_manual",
            "offboard flight, the stream stops for 3 s and resumes; no manual control",
            stream_loss,
            "hazard",
            "stream lost in OFFBOARD (failsafe, then back to OFFBOARD)",
            ("OFB103",),
        ),
        Scenario(
            "loss_manual",
            "as loss_no_manual with a MAVLink joystick at 10 Hz (manual control present)",
            stream_loss,
            "hazard",
            "stream lost in OFFBOARD (failsafe, then back to OFFBOARD)",
            ("OFB103",),
            manual=True,
        ),
        Scenario(
            "stall_1_5s",
            "offboard flight, the setpoint loop stalls 1.5 s mid-air",
            stall_1_5s,
            "hazard",
            "stream lost in OFFBOARD for 0.5 s",
            ("OFB103",),
        ),
        Scenario(
            "disarmed_switch_no_stream",
            "no stream: switch to OFFBOARD while disarmed (accepted), arm (refused)",
            disarmed_switch_no_stream,
            "hazard",
            "arm in OFFBOARD without a stream, refused",
            ("OFB201",),
        ),
        Scenario(
            "switch_no_stream_flying",
            "auto takeoff, then a switch to OFFBOARD with no stream while flying (refused)",
            switch_no_stream_flying,
            "hazard",
            "switch to OFFBOARD without a stream while armed, refused",
            ("OFB201",),
        ),
        Scenario(
            "disarm_in_flight",
            "offboard flight, a disarm command mid-air (PX4: 'not landed'), land",
            disarm_in_flight,
            "clean",
        ),
        Scenario(
            "acceleration_only",
            "acceleration-only setpoints: switch, arm, up, brake, hover, land",
            acceleration_only,
            "clean",
        ),
        Scenario(
            "attitude",
            "SET_ATTITUDE_TARGET level at 0.3 thrust: switch, arm, 4 s, land",
            attitude,
            "clean",
        ),
        Scenario(
            "attitude_no_thrust",
            "SET_ATTITUDE_TARGET with the thrust ignored, from the ground: switch, arm, disarm",
            attitude_no_thrust,
            "hazard",
            "an attitude setpoint without thrust: thrust 0 up to 1.17, dropped on 1.18 and main"
            " (no keep-alive, the arm refused)",
            ("OFB606",),
            shown_in=(".tlog",),
        ),
        Scenario(
            "enu_frame",
            "auto takeoff, then LOCAL_ENU (frame 4) setpoints and a switch (refused)",
            enu_frame,
            "hazard",
            "coordinate_frame 4 is dropped by PX4 (no keep-alive), switch refused",
            ("OFB601", "OFB201"),
        ),
        Scenario(
            "enu_z_from_ground",
            "z = +2.5 (ENU 'up') sent in LOCAL_NED from the ground: 2.5 m below ground",
            enu_z_from_ground,
            "hazard",
            "a climb written in ENU, from the ground",
            ("OFB404",),
        ),
        Scenario(
            "enu_z_airborne",
            "offboard at 2.5 m, then z = +2.5 (ENU 'up') in LOCAL_NED: dives into the ground",
            enu_z_airborne,
            "hazard",
            "z flips sign mid-air (ENU thinking), airborne",
            ("OFB404",),
        ),
        Scenario(
            "one_setpoint_then_switch",
            "one setpoint, then switch and arm at once (accepted: no minimum stream)",
            one_setpoint_then_switch,
            "clean",
        ),
        Scenario(
            "frozen_velocity",
            "offboard at 2.5 m, then velocity 2 m/s frozen for 20 s while the stream keeps coming",
            frozen_velocity,
            "hazard",
            "a motion command frozen for 20 s",
            ("OFB107",),
        ),
        Scenario(
            "switch_to_broadcast",
            "stream, DO_SET_MODE OFFBOARD to system 0 component 0, arm: offboard from 1.18 only",
            switch_to_broadcast,
            "hazard",
            "a switch PX4 does not take (up to 1.17): the vehicle arms in Hold, never offboard",
            ("OFB204",),
            shown_in=(".tlog",),
            hazard_until=(1, 18),
        ),
        Scenario(
            "hold_with_unknown_sub_mode",
            "offboard flight, then DO_SET_MODE AUTO sub-mode 42 (no such mode) as a hold, land",
            hold_with_unknown_sub_mode,
            "hazard",
            "a mode request PX4 cannot honour: the vehicle stays in OFFBOARD",
            ("OFB205",),
        ),
        Scenario(
            "hex_offboard",
            "hexacopter: stream, switch, arm, climb to 2.5 m, fly 3 m and back, land",
            clean_offboard,
            "clean",
            vehicle="hex",
        ),
        Scenario(
            "vtol_offboard",
            "standard VTOL: offboard takeoff in MC to 20 m, DO_VTOL_TRANSITION to FW in OFFBOARD,"
            " FW position setpoints, back to MC, land",
            vtol_offboard,
            "clean",
            vehicle="vtol",
        ),
        Scenario(
            "vtol_loss",
            "standard VTOL: the stream stops 2 s hovering in MC, then 2 s cruising in FW",
            vtol_loss,
            "hazard",
            "stream lost in OFFBOARD in each VTOL phase (failsafe, then back to OFFBOARD)",
            ("OFB103",),
            vehicle="vtol",
        ),
        Scenario(
            "vtol_fw_glide",
            "standard VTOL in FW flight: position setpoints with z NaN (1.18: glide), then z again",
            vtol_fw_glide,
            "clean",
            vehicle="vtol",
            flies_on=VTOL_FW_FLIES_ON,
        ),
        Scenario(
            "vtol_fw_types",
            "standard VTOL in FW flight: the fixed-wing setpoint types (12288 loiter, 292 glide,"
            " 8192 land, 16384 idle), 4 s each, then the position setpoint again",
            vtol_fw_types,
            "clean",
            vehicle="vtol",
            flies_on=VTOL_FW_FLIES_ON,
        ),
        Scenario(
            "vtol_fw_takeoff_type",
            "standard VTOL in FW flight: the takeoff setpoint type (4096) 6 s, then the position"
            " setpoint again",
            vtol_fw_takeoff_type,
            "clean",
            vehicle="vtol",
            flies_on=VTOL_FW_FLIES_ON,
        ),
        Scenario(
            "vtol_fw_velocity",
            "standard VTOL in FW flight: a velocity-only setpoint (10 m/s east) 8 s, then the"
            " position setpoint again",
            vtol_fw_velocity,
            "hazard",
            "a velocity-only setpoint in FW flight: the docs say fixed-wing takes the position"
            " only (PX4 did not turn to it)",
            ("OFB604",),
            shown_in=(".tlog",),
            vehicle="vtol",
            flies_on=VTOL_FW_FLIES_ON,
        ),
        Scenario(
            "tailsitter_offboard",
            "tailsitter: as vtol_offboard, with FW_USE_AIRSPD 0 (the transition timed, not on"
            " the airspeed SIH's tailsitter never shows) and the 1.18 airframe's right elevon",
            vtol_offboard,
            "clean",
            params=TAILSITTER_PARAMS,
            vehicle="tailsitter",
            flies_on=TAILSITTER_FLIES_ON,
        ),
        Scenario(
            "tailsitter_loss",
            "tailsitter: the stream stops 2 s hovering in MC, then 2 s in FW (FW_USE_AIRSPD 0,"
            " the 1.18 airframe's right elevon)",
            vtol_loss,
            "hazard",
            "stream lost in OFFBOARD in each VTOL phase (failsafe, then back to OFFBOARD)",
            ("OFB103",),
            params=TAILSITTER_PARAMS,
            vehicle="tailsitter",
            flies_on=TAILSITTER_FLIES_ON,
        ),
        Scenario(
            "fw_offboard",
            "airplane: runway takeoff (AUTO_TAKEOFF) to Hold at 25 m, stream, switch to OFFBOARD"
            " in the air, a position setpoint 400 m ahead, Hold",
            fw_offboard,
            "clean",
            params=AIRPLANE_PARAMS,
            vehicle="fw",
            flies_on=AIRPLANE_FLIES_ON,
            params_on=AIRPLANE_PARAMS_ON,
        ),
        Scenario(
            "fw_loss",
            "airplane: takeoff, OFFBOARD, the stream stops 3 s and resumes, Hold",
            fw_loss,
            "hazard",
            "stream lost in OFFBOARD (failsafe, then back to OFFBOARD)",
            ("OFB103",),
            params=AIRPLANE_PARAMS,
            vehicle="fw",
            flies_on=AIRPLANE_FLIES_ON,
            params_on=AIRPLANE_PARAMS_ON,
        ),
        Scenario(
            "fw_gate",
            "airplane on the ground: stream, switch to OFFBOARD, arm, the stream stops 3 s and"
            " resumes, disarm (forced if PX4 counts it flying)",
            fw_gate,
            "hazard",
            "stream lost in OFFBOARD (failsafe, then back to OFFBOARD)",
            ("OFB103",),
            params=AIRPLANE_OUTPUTS,
            vehicle="fw",
        ),
        Scenario(
            "fw_takeoff_type",
            "airplane on the ground: the takeoff setpoint type (4096) 200 m ahead and 30 m up,"
            " switch to OFFBOARD, arm, 15 s, disarm (forced if PX4 counts it flying)",
            fw_takeoff_type,
            "hazard",
            "the takeoff setpoint type is not read (PX4 1.12+): no runway takeoff, the setpoint"
            " is flown as a position with zero velocity (full throttle on the ground)",
            ("OFB603",),
            params=AIRPLANE_OUTPUTS,
            shown_in=(".tlog",),
            vehicle="fw",
            flies_on=FW_TAKEOFF_TYPE_ON,
        ),
        Scenario(
            "rover_offboard",
            "Ackermann rover: offboard position setpoint 10 m north, then velocity, stop, disarm",
            rover_offboard,
            "clean",
            vehicle="rover-ackermann",
        ),
        Scenario(
            "rover_loss",
            "Ackermann rover: driving to a position setpoint, the stream stops 3 s and resumes",
            rover_loss,
            "hazard",
            "stream lost in OFFBOARD (failsafe, then back to OFFBOARD)",
            ("OFB103",),
            vehicle="rover-ackermann",
        ),
        Scenario(
            "sticks_moved",
            "offboard hover with a MAVLink joystick; the pitch stick ramps to 0.6 and back",
            sticks_moved,
            "clean",
            manual=True,
        ),
        Scenario(
            "sticks_moved_override",
            "as sticks_moved with COM_RC_OVERRIDE 3 (1.14-1.17: sticks also end OFFBOARD)",
            sticks_moved,
            "clean",
            manual=True,
            params={"COM_RC_OVERRIDE": 3.0},
        ),
    )
}


EVERY_SCENARIO_ON = ("1.16.2", "1.18.0-alpha1")
"""The releases every scenario runs on (a long-supported one and the newest) in the corpus and
in ``make test-sitl``; the other releases run the scenarios whose outcome depends on the
release (the loss action and manual control, the acks, the disarmed switch, the estimate an
acceleration needs, the minimum stream)."""
RELEASE_DEPENDENT = (
    "clean_offboard",
    "loss_no_manual",
    "loss_manual",
    "stall_1_5s",
    "disarmed_switch_no_stream",
    "switch_no_stream_flying",
    "disarm_in_flight",
    "acceleration_only",
    "one_setpoint_then_switch",
    "switch_to_broadcast",
    "sticks_moved",
    "attitude_no_thrust",
)


VEHICLE_RELEASES = (
    "1.14.4",
    "1.15.4",
    "1.16.2",
    "1.17.0",
    "1.17.0-ros2-rover",
    "1.18.0-alpha1",
    "1.18.0-beta1-head",
    "main-2026-08-13",
)
"""The bundles the other vehicles' scenarios run on: every bundle with the airframe (the
airplane and the tailsitter are in all; the standard VTOL came with 1.16's SIH, the hexacopter
and the rover with 1.17.0's; the rover flies only where the bundle has its module:
``airframes.why_not``; a program only on its ``flies_on``)."""


SIM_STALLS = (
    "PX4 main-2026-08-13's SIH stops its clock once the quadrotor is in OFFBOARD disarmed without"
    " a setpoint it takes (SIH lockstep: timed out waiting for actuator_outputs_sim): nothing"
    " after the switch is answered, so the run shows nothing of the gate"
)
DOES_NOT_RUN: dict[tuple[str, str], str] = {
    ("main-", "disarmed_switch_no_stream"): SIM_STALLS,
    ("main-", "attitude_no_thrust"): SIM_STALLS,
}
"""(bundle name prefix, scenario): why that bundle cannot run the scenario (seen 2026-12)."""


def why_not_run(release: str, name: str) -> str | None:
    """Why the bundle ``release`` cannot run scenario ``name`` (None: it can)."""
    for (prefix, scenario), reason in DOES_NOT_RUN.items():
        if scenario == name and release.startswith(prefix):
            return reason
    return None


def scenarios_for(release: str) -> list[str]:
    """The multicopter scenarios the matrix runs on ``release``."""
    if release in EVERY_SCENARIO_ON:
        return [name for name, s in SCENARIOS.items() if s.vehicle == "quad"]
    return list(RELEASE_DEPENDENT)


def vehicle_scenarios() -> list[str]:
    """The scenarios of the other vehicles (run where ``airframes.why_not`` allows)."""
    return [name for name, s in SCENARIOS.items() if s.vehicle != "quad"]
