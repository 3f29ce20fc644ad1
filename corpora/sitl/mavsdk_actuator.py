"""A MAVSDK program that hovers in offboard on a velocity setpoint, then hands the actuators a
payload command through ``Offboard.set_actuator_control``, driven through the real ``mavsdk``
package from PyPI (4.x, the native C++ library in-process). Run with that package's Python:

    /tmp/mavsdk4/bin/python corpora/sitl/mavsdk_actuator.py udpin://127.0.0.1:14640

The sequence: wait until ``health_all_ok``, arm, take off, wait until in air; set a zero
velocity, ``start()`` (OFFBOARD), hover 3 s; then ``set_actuator_control`` with both control
groups set, which MAVSDK streams instead of the velocity, as ``SET_ACTUATOR_CONTROL_TARGET``,
one message per group at 20 Hz (``offboard_impl.cpp``). PX4 1.14+ ignores that message: the
keep-alive stops and PX4 runs its offboard-loss failsafe while MAVSDK keeps sending. After 5 s
the program stops offboard (Hold), lands, waits until on the ground, and 3 s more.
"""

from __future__ import annotations

import sys
import time


def say(text: str) -> None:
    print(text, flush=True)


def run(url: str) -> int:
    from mavsdk import ComponentType, Configuration, Mavsdk
    from mavsdk.plugins.action import Action
    from mavsdk.plugins.offboard import Offboard
    from mavsdk.plugins.offboard.offboard import (
        ActuatorControl,
        ActuatorControlGroup,
        VelocityNedYaw,
    )
    from mavsdk.plugins.telemetry import Telemetry

    sdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
    sdk.add_any_connection(url)
    system = sdk.first_autopilot(10.0)
    if system is None:
        say("Timed out waiting for system")
        return 1
    action, offboard, telemetry = Action(system), Offboard(system), Telemetry(system)
    while not telemetry.health_all_ok():
        say("Waiting for system to be ready")
        time.sleep(1)
    action.arm()
    say("Armed")
    action.takeoff()
    deadline = time.monotonic() + 13
    while not telemetry.in_air() and time.monotonic() < deadline:
        time.sleep(0.1)
    if not telemetry.in_air():
        say("Takeoff timed out.")
        return 1
    time.sleep(3)

    offboard.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 0.0))
    offboard.start()
    say("Offboard started (velocity NED)")
    time.sleep(3)

    # group 0: roll, pitch, yaw, thrust and four spare controls; group 1: a gripper on its
    # sixth control. MAVSDK sends both groups (no control is NaN) at its 20 Hz.
    controls = ActuatorControl(
        [
            ActuatorControlGroup([0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0]),
            ActuatorControlGroup([0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        ]
    )
    offboard.set_actuator_control(controls)
    say("Actuator control set")
    time.sleep(5)
    try:
        offboard.stop()
        say("Offboard stopped")
    except Exception as error:  # PX4 has left OFFBOARD already: stop() may be refused
        say(f"Offboard stop: {error}")

    action.land()
    while telemetry.in_air():
        say("Vehicle is landing...")
        time.sleep(1)
    say("Landed!")
    time.sleep(3)
    return 0


if __name__ == "__main__":
    sys.exit(run(sys.argv[1]))
