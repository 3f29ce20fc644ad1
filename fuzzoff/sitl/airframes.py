"""Which vehicle a SITL run flies: PX4's SIH airframes, and whether a build can fly each.

PX4 picks the simulated airframe at boot from ``PX4_SIM_MODEL`` (the name of a file under
``etc/init.d-posix/airframes/``, after its number). A build can fly an airframe when it ships
that file and, for a rover, was built with the rover's module (``bin/commands.txt``); a few
builds have an airframe that does not fly, each said here with the reason.
"""

from __future__ import annotations

from dataclasses import field

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import ProfileError, vehicle_type_for
from fuzzoff.sitl import bundle


@dataclass(frozen=True, slots=True)
class Airframe:
    vehicle: str
    """What ``--vehicle`` takes."""
    model: str
    """``PX4_SIM_MODEL``: the SIH airframe."""
    fuzzoff_vehicle: str
    """The vehicle type the gate model and the rules judge it as (``fuzzoff profiles``)."""
    module: str | None = None
    """A PX4 module the build needs beside the airframe file."""
    fixes: dict[str, float] = field(default_factory=dict)
    """Parameters every run sets so that SIH flies the airframe as PX4 means it, on every
    build (where a build's airframe has them right already, they are its own values): the
    scenarios of the vehicle and a live campaign on it (docs/sitl.md, "Other vehicles")."""
    fixes_on: dict[str, dict[str, float]] = field(default_factory=dict)
    """More ``fixes`` on the builds whose bundle name starts with the key (``fixes_for``)."""
    boot_params: dict[str, float] = field(default_factory=dict)
    """Parameters PX4 must have from its boot (``PX4_PARAM_<NAME>``, read by the rcS of 1.16 and
    later; 1.14 and 1.15 ignore it): what a module reads only when it starts."""


AIRPLANE_OUTPUTS = {
    "PWM_MAIN_FUNC1": 201.0,
    "PWM_MAIN_FUNC2": 202.0,
    "PWM_MAIN_FUNC3": 203.0,
    "PWM_MAIN_FUNC4": 101.0,
    "PWM_MAIN_FUNC5": 0.0,
    "PWM_MAIN_FUNC6": 0.0,
}
"""The SIH airplane's outputs as SIH reads them (servos on outputs 1-3, the motor on 4): the
1.16 airframe's mapping. The 1.14 and 1.15 airframes put them on outputs 3-6; there SIH's
state went NaN within 0.1 s of the arm (attitude, then position invalid) and PX4 flew flight
termination. With this mapping the arm, the loss and the failsafe are PX4's own; on 1.16 and
later it is what the airframe sets already."""

AIRPLANE_THRUST = {"SIH_F_T_MAX": 6.0}
"""The airplane's propeller thrust, 6 N, as its airframe means it on every build. Until 1.17
SIH's airplane pulled ``SIH_T_MAX`` (the airframe sets 6 N); 1.18's SIH takes a fixed wing's,
a tailsitter's and a pusher's thrust from ``SIH_F_T_MAX`` instead (default 2 N) and keeps
``SIH_T_MAX`` for multicopter rotors, while the 1.18 airframe still sets only ``SIH_T_MAX``: with
2 N the airplane rolled at 5.4 m/s and never rotated. On PX4 before 1.18 the run sets
``SIH_T_MAX`` (``session.RENAMED``)."""

AIRPLANE_1_14 = {
    "CA_SV_CS0_TRQ_R": 1.0,
    "CA_SV_CS0_TYPE": 15.0,
    "CA_SV_CS1_TRQ_P": -1.0,
    "CA_ROTOR0_PX": 0.3,
    "FW_TKO_PITCH_MIN": 0.0,
    "FW_RR_P": 0.05,
    "FW_RR_I": 2.0,
    "FW_RR_FF": 0.0,
    "FW_RR_IMAX": 1.0,
    "FW_PR_P": 0.08,
    "FW_PR_I": 2.5,
    "FW_PR_FF": 0.0,
    "FW_PR_IMAX": 1.0,
    "FW_YR_P": 0.05,
    "FW_YR_I": 3.0,
    "FW_YR_FF": 0.0,
    "FW_YR_IMAX": 1.0,
}
"""What makes the airplane of 1.14.4 and 1.15.4 take off and fly (docs/sitl.md). Their SIH
pitches the nose up on a negative elevator output: with the airframe's ``CA_SV_CS1_TRQ_P`` +1
the pitch loop ran away at the lift-off (10-11 m/s, the pitch rate 10 to 178 degrees/s in
0.2 s against a full nose-down command) and PX4's failure detector disarmed it; the 1.16 SIH
takes the same +1 the other way round. Their SIH also holds a grounded airplane level (roll and
pitch 0, no rotation: ``equations_of_motion``), so a runway takeoff's rotation cannot happen
and its nose-up elevator only pressed the airplane down (12 m/s for 30 s, no lift-off): with
``FW_TKO_PITCH_MIN`` 0 it leaves the ground level at about 11 m/s and climbs. The aileron (one
channel, +1 instead of the left aileron's -0.5), the rotor's position and the rate gains are
the 1.16 airframe's."""

AIRPLANE_BOOT = {"SIH_LOC_H0": 0.0}
"""SIH's ground at 0 m above sea level instead of 489.4 m (``SIH_LOC_H0``, read once when SIH
starts). PX4's fixed-wing altitude controller (TECS) starts its altitude reference at 0 m, before
the estimator has its origin, and ramps it at the climb rate from there (on the ground too) and
is not reset at the takeoff: 10 s after boot it was 57 m AMSL with the airplane at 506 m, and
after the runway takeoff TECS sank to reach it (pitch -30 degrees, throttle near 0, on the
ground 6-8 s later) in every mode that leaves the altitude to TECS (OFFBOARD, Hold, Return).
With the ground at 0 m its reference starts where the airplane is; it then held 25-27 m in
OFFBOARD (1.17.0). 1.14 and 1.15 do not take the boot parameter (their airplane does not fly)."""

TAILSITTER_FIXES = {"FW_USE_AIRSPD": 0.0, "CA_SV_CS1_TRQ_P": -0.5, "CA_SV_CS1_TRQ_Y": -0.5}
"""SIH's tailsitter (``sihsim_xvert``) never shows the transition airspeed: the airspeed PX4
validated stayed at 0.1-5 m/s while it flew 7 m/s over ground, the front transition waited
for VT_ARSP_TRANS (10 m/s) and PX4 quad-chuted back to MC 6.6 s in (1.18 head). Without the
airspeed (FW_USE_AIRSPD 0) PX4 times the transition (VT_F_TR_OL_TM) and it reached FW in
3.4 s, then held 28 m at 10.7 m/s. The right elevon's pitch and yaw torques are -0.5 as the
1.18 head's and main's airframe has them: the airframes of 1.14.4 to 1.18.0-alpha1 give +0.5,
SIH deflects the two elevons with opposite signs, their pitch then cancels, and the tailsitter
rose 0.1-1.3 m at most in OFFBOARD (PX4 counted it landed); with -0.5 it climbed to 20 m and
flew FW on every bundle. On 1.14 FW_USE_AIRSPD is FW_ARSP_MODE (``session.RENAMED``)."""

AIRFRAMES: dict[str, Airframe] = {
    a.vehicle: a
    for a in (
        Airframe("quad", "sihsim_quadx", "mc"),
        Airframe("hex", "sihsim_hex", "mc"),
        Airframe(
            "fw",
            "sihsim_airplane",
            "fw",
            fixes=AIRPLANE_OUTPUTS | AIRPLANE_THRUST,
            fixes_on={"1.14.": AIRPLANE_1_14, "1.15.": AIRPLANE_1_14},
            boot_params=AIRPLANE_BOOT,
        ),
        Airframe("tailsitter", "sihsim_xvert", "vtol", fixes=TAILSITTER_FIXES),
        Airframe("vtol", "sihsim_standard_vtol", "vtol"),
        Airframe("rover-ackermann", "sihsim_rover_ackermann", "rover-ackermann", "rover_ackermann"),
    )
}
DEFAULT = "quad"

DOES_NOT_FLY: dict[tuple[str, str], str] = {
    (
        "main",
        "sihsim_rover_ackermann",
    ): "the Ackermann rover on main (2026-08-13) stalls PX4's simulated clock after the arm"
    " (SIH lockstep waits for actuator outputs the rover controller sends at 100 Hz: 40 ms of"
    " PX4 time in 60 s); fly it on 1.17.0-ros2-rover or 1.18.0-beta1-head"
}
"""(bundle name prefix, airframe) -> why that build cannot fly it, though it has it."""


def fixes_for(airframe: Airframe, release: str) -> dict[str, float]:
    """The fixes a run of ``airframe`` sets on the bundle ``release``: its own, then those of
    the release (``Airframe.fixes_on``)."""
    return on_release(airframe.fixes, airframe.fixes_on, release)


def on_release(
    base: dict[str, float], on: dict[str, dict[str, float]], release: str
) -> dict[str, float]:
    """``base``, then the parameters of ``on`` whose key (a bundle name prefix) ``release``
    starts with, later ones winning."""
    extra = [params for prefix, params in on.items() if release.startswith(prefix)]
    return {k: v for params in (base, *extra) for k, v in params.items()}


class AirframeError(bundle.BundleError):
    """A vehicle the build cannot fly: one line for the user."""


def airframe_for(vehicle: str) -> Airframe:
    try:
        return AIRFRAMES[vehicle]
    except KeyError:
        raise AirframeError(
            f"--vehicle {vehicle}: no such SITL vehicle; one of {', '.join(AIRFRAMES)}"
        ) from None


def airframe_named(name: str) -> Airframe:
    """The airframe for a SITL vehicle (``fw``) or a fuzzoff vehicle type (``mc``,
    ``fixed-wing``: the first airframe judged as that type); ``AirframeError`` for a type no SIH
    airframe flies (a differential rover)."""
    if name in AIRFRAMES:
        return AIRFRAMES[name]
    try:
        vehicle = vehicle_type_for(name)
    except ProfileError:
        vehicle = None
    found = next((a for a in AIRFRAMES.values() if a.fuzzoff_vehicle == vehicle), None)
    if found is None:
        raise AirframeError(
            f"--vehicle {name}: no SIH airframe flies it; one of {', '.join(AIRFRAMES)}"
        )
    return found


def why_not(build: bundle.Build, airframe: Airframe) -> str | None:
    """Why ``build`` cannot fly ``airframe`` (None: it can)."""
    folder = build.folder / "etc" / "init.d-posix" / "airframes"
    if not any(p.name.endswith("_" + airframe.model) for p in folder.glob("*")):
        return f"PX4 {build.release} has no SIH airframe {airframe.model}"
    if airframe.module is not None:
        commands = build.folder / "bin" / "commands.txt"
        text = commands.read_text(errors="replace") if commands.exists() else ""
        names = set(text.split())
        if not {airframe.module, f"px4-{airframe.module}"} & names:
            return f"PX4 {build.release} was built without the {airframe.module} module"
    for (prefix, model), reason in DOES_NOT_FLY.items():
        if model == airframe.model and build.folder.name.startswith(prefix):
            return reason
    return None


def boot_env(
    build: bundle.Build, vehicle: str, env: dict[str, str] | None = None
) -> dict[str, str]:
    """``env`` with what makes PX4 boot ``vehicle`` (``PX4_SIM_MODEL`` and the airframe's
    ``boot_params``, which ``env`` may override); ``AirframeError`` when the build cannot fly it.
    The default quadrotor adds nothing (PX4's own default)."""
    airframe = airframe_for(vehicle)
    reason = why_not(build, airframe)
    if reason is not None:
        raise AirframeError(f"--vehicle {vehicle}: {reason}")
    if vehicle == DEFAULT:
        return dict(env or {})
    boot = {f"PX4_PARAM_{k}": f"{v:g}" for k, v in airframe.boot_params.items()}
    return {**boot, **(env or {}), "PX4_SIM_MODEL": airframe.model}
