"""MAVSDK's offboard example (``cpp/examples/offboard/offboard.cpp`` in mavlink/MAVSDK), driven
through the real ``mavsdk`` package from PyPI: 3.x (gRPC, its bundled ``mavsdk_server``) or
4.x (the native C++ library in-process). Run with that package's Python, not fuzzoff's:

    /tmp/mavsdk4/bin/python corpora/sitl/mavsdk_offboard.py udpin://127.0.0.1:14640

The sequence is the example's ``main``: wait until ``health_all_ok``, arm, take off, wait until
in air, then ``offb_ctrl_attitude`` and ``offb_ctrl_ned`` as the source has them (each sets a
setpoint, then ``start()``, changes it with sleeps between, then ``stop()``, which switches to
Hold), land, wait until on the ground, and 3 s more. MAVSDK itself streams the newest setpoint
at 20 Hz and sends each new one at once (``offboard_impl.cpp``). The example's global-position
(30 s) and body-velocity (55 s) segments are left out so that the recordings stay under 1 MB.
"""

from __future__ import annotations

import asyncio
import math
import sys
import time

import mavsdk

MAJOR = int(mavsdk.__version__.split(".")[0]) if hasattr(mavsdk, "__version__") else 3


def say(text: str) -> None:
    print(text, flush=True)


def run_native(url: str) -> int:
    """mavsdk 4.x: the C++ API one to one."""
    from mavsdk import ComponentType, Configuration, Mavsdk
    from mavsdk.plugins.action import Action
    from mavsdk.plugins.offboard import Offboard
    from mavsdk.plugins.offboard.offboard import Attitude, VelocityNedYaw
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

    # offb_ctrl_attitude
    roll = Attitude(30.0, 0.0, 0.0, 0.6)
    offboard.set_attitude(roll)
    offboard.start()
    say("Offboard started (attitude)")
    offboard.set_attitude(roll)
    time.sleep(2)
    offboard.set_attitude(Attitude(0.0, 0.0, 0.0, 0.6))
    time.sleep(1)
    offboard.set_attitude(Attitude(-30.0, 0.0, 0.0, 0.6))
    time.sleep(2)
    offboard.set_attitude(Attitude(0.0, 0.0, 0.0, 0.6))
    time.sleep(2)
    offboard.stop()
    say("Offboard stopped")

    # offb_ctrl_ned
    offboard.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 0.0))
    offboard.start()
    say("Offboard started (velocity NED)")
    offboard.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 90.0))
    time.sleep(1)
    step, cycle = 0.01, 2.0 * math.pi
    for i in range(2 * int(cycle / step)):
        offboard.set_velocity_ned(VelocityNedYaw(5.0 * math.sin(i * step), 0.0, 0.0, 90.0))
        time.sleep(0.01)
    offboard.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 270.0))
    time.sleep(2)
    offboard.set_velocity_ned(VelocityNedYaw(0.0, 0.0, -2.0, 180.0))
    time.sleep(4)
    offboard.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 0.0))  # the source's down_and_north{}
    time.sleep(4)
    offboard.stop()
    say("Offboard stopped")

    action.land()
    while telemetry.in_air():
        say("Vehicle is landing...")
        time.sleep(1)
    say("Landed!")
    time.sleep(3)
    return 0


async def run_grpc(url: str) -> int:
    """mavsdk 3.x: the same sequence through mavsdk_server."""
    from mavsdk import System
    from mavsdk.offboard import Attitude, VelocityNedYaw

    drone = System()
    await drone.connect(system_address=url)
    async for state in drone.core.connection_state():
        if state.is_connected:
            break
    async for ok in drone.telemetry.health_all_ok():
        if ok:
            break
        say("Waiting for system to be ready")
    await drone.action.arm()
    say("Armed")
    await drone.action.takeoff()

    async def in_air() -> None:
        async for flying in drone.telemetry.in_air():
            if flying:
                return

    try:
        await asyncio.wait_for(in_air(), 13)
    except TimeoutError:
        say("Takeoff timed out.")
        return 1

    off = drone.offboard
    await off.set_attitude(Attitude(30.0, 0.0, 0.0, 0.6))
    await off.start()
    say("Offboard started (attitude)")
    await off.set_attitude(Attitude(30.0, 0.0, 0.0, 0.6))
    await asyncio.sleep(2)
    await off.set_attitude(Attitude(0.0, 0.0, 0.0, 0.6))
    await asyncio.sleep(1)
    await off.set_attitude(Attitude(-30.0, 0.0, 0.0, 0.6))
    await asyncio.sleep(2)
    await off.set_attitude(Attitude(0.0, 0.0, 0.0, 0.6))
    await asyncio.sleep(2)
    await off.stop()
    say("Offboard stopped")

    await off.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 0.0))
    await off.start()
    say("Offboard started (velocity NED)")
    await off.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 90.0))
    await asyncio.sleep(1)
    step, cycle = 0.01, 2.0 * math.pi
    for i in range(2 * int(cycle / step)):
        await off.set_velocity_ned(VelocityNedYaw(5.0 * math.sin(i * step), 0.0, 0.0, 90.0))
        await asyncio.sleep(0.01)
    await off.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 270.0))
    await asyncio.sleep(2)
    await off.set_velocity_ned(VelocityNedYaw(0.0, 0.0, -2.0, 180.0))
    await asyncio.sleep(4)
    await off.set_velocity_ned(VelocityNedYaw(0.0, 0.0, 0.0, 0.0))
    await asyncio.sleep(4)
    await off.stop()
    say("Offboard stopped")

    await drone.action.land()
    async for flying in drone.telemetry.in_air():
        if not flying:
            break
        say("Vehicle is landing...")
    say("Landed!")
    await asyncio.sleep(3)
    return 0


if __name__ == "__main__":
    target = sys.argv[1]
    sys.exit(run_native(target) if MAJOR >= 4 else asyncio.run(run_grpc(target)))
