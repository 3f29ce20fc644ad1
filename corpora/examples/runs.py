"""Fly the example clients against PX4 SITL and keep what PX4 answered.

``.venv/bin/python corpora/examples/runs.py NAME... [--instance 4]`` starts the scenario's PX4
bundle (``../shared/px4-sitl``, one instance, a private folder under /tmp), waits until PX4 is
ready to arm, runs the scenario (ground-station steps and the client) and writes into ``runs/``:

* ``NAME.client.json.gz``: the scenario, PX4's system id, and every message the client
  published (PX4 time in µs, topic, fields), in order;
* ``NAME.tlog``: the MAVLink exchange the driver had (``px4link.py``);
* ``NAME.ulg``: PX4's own ULog, cut to the topics the recording takes from it.

``build.py`` turns these into the recordings. Runs take real time (the ten-minute hold about
eleven minutes); PX4 is stopped at the end of each, whatever happens.
"""

from __future__ import annotations

import argparse
import gzip
import json
import math
import os
import shutil
import struct
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

import clients as cl
from px4link import Link, VehicleView, px4
from pymavlink import mavutil
from pyulog import ULog

HERE = Path(__file__).resolve().parent
RUNS = HERE / "runs"
WORK = Path(os.environ.get("FUZZOFF_EXAMPLES_WORK", "/tmp/fuzzoff-examples"))

ULOG_TOPICS = (
    "vehicle_status",
    "vehicle_command",
    "vehicle_command_ack",
    "vehicle_local_position",
    "vehicle_land_detected",
    "failsafe_flags",
)
"""What the recordings take from PX4 (``/fmu/out`` topics of the bridge), and the commands PX4
received."""

MAX_LATE_US = 50_000
"""A client cycle that ran later than this after its tick makes the run start again."""


MAVROS_SYSTEM, MAVROS_COMPONENT = 1, 191
"""The driver's MAVLink ids (an onboard computer on system 1), for both kinds of client."""


@dataclass
class Scenario:
    """One PX4 run: which release and airframe, the ground-station steps, the client."""

    name: str
    release: str
    client: Callable[[], cl.Client]
    transport: str
    """``ros2`` (px4_msgs over the uXRCE-DDS bridge) or ``mavros``."""
    duration_s: float
    takeoff: bool = False
    gcs: list[tuple[float, str]] = field(default_factory=list)
    """(seconds after the client started, step): ``offboard``, ``hold``, ``land``, ``goto_mode``."""
    after_s: float = 4.0
    model: str = "sihsim_quadx"
    """The airframe (every scenario flies the SIH quadrotor; the rovers too, see README.md)."""
    local_position_hz: float = 10.0
    """vehicle_local_position is logged at about 125 Hz; this much is kept (files under 1 MB)."""


def frozen_planner(seconds: float) -> tuple[float, float, float]:
    """A planner that eases forward for 6 s, then dies: its library keeps re-sending 2 m/s."""
    if seconds < 6.0:
        return (2.0 * (1 - math.cos(math.pi * seconds / 6.0)) / 2, 0.0, 0.0)
    return (2.0, 0.0, 0.0)


SCENARIOS: dict[str, Scenario] = {
    s.name: s
    for s in (
        # the examples as their sources run them; a ROS 2 recording stops with the client
        # (the launch file's Ctrl-C), so after_s is only what the bag recorder lags behind
        Scenario(
            "px4_ros_com_offboard_control",
            "1.16.2",
            cl.OffboardControlCpp,
            "ros2",
            40.0,
            after_s=0.3,
        ),
        Scenario(
            "px4_ros_com_offboard_control_py",
            "1.15.4",
            cl.OffboardControlPy,
            "ros2",
            60.0,
            after_s=14.0,
        ),
        Scenario(
            "px4_ros_com_ten_minute_hold",
            "1.17.0",
            cl.OffboardControlCpp,
            "ros2",
            600.0,
            after_s=0.3,
            local_position_hz=1.0,
        ),
        Scenario(
            "px4_offboard_circle_after_takeoff",
            "1.16.2",
            cl.CircleOffboard,
            "ros2",
            56.0,
            takeoff=True,
            gcs=[(3.0, "offboard"), (33.0, "land")],
            after_s=0.3,
        ),
        Scenario("mavros_offb_node", "1.14.4", cl.MavrosOffbNode, "mavros", 40.0, after_s=0.3),
        Scenario(
            "interface_lib_goto",
            "1.16.2",
            cl.GotoMode,
            "ros2",
            50.0,
            takeoff=True,
            gcs=[(2.0, "goto_mode"), (45.0, "land")],
            after_s=10.0,
        ),
        Scenario(
            "rover_speed_attitude",
            "1.17.0",
            cl.RoverSpeedAttitude,
            "ros2",
            10.0,
            after_s=0.3,
        ),
        # hazards, each on one of these clients
        Scenario(
            "hazard_frozen_velocity",
            "1.16.2",
            lambda: cl.OffboardControlCpp(
                velocity_from=8.0, velocity_position=None, planner=frozen_planner
            ),
            "ros2",
            34.0,
            gcs=[(34.0, "hold")],
            after_s=5.0,
        ),
        Scenario(
            "hazard_stall_mid_air",
            "1.16.2",
            lambda: cl.OffboardControlCpp(stall=(15.0, 16.5)),
            "ros2",
            25.0,
            after_s=0.3,
        ),
        Scenario(
            "hazard_enu_z_from_ground",
            "1.16.2",
            lambda: cl.OffboardControlCpp(position=(0.0, 0.0, 5.0)),
            "ros2",
            15.0,
            after_s=0.3,
        ),
        Scenario(
            "hazard_enu_z_airborne",
            "1.16.2",
            lambda: cl.CircleOffboard(altitude=-5.0),
            "ros2",
            25.0,
            takeoff=True,
            gcs=[(3.0, "offboard")],
            after_s=0.3,
        ),
        Scenario(
            "hazard_nan_pattern_velocity_zero_position",
            "1.16.2",
            lambda: cl.OffboardControlCpp(velocity_from=12.0, velocity=(1.0, 0.0, 0.0)),
            "ros2",
            30.0,
            after_s=0.3,
        ),
        Scenario(
            "hazard_switch_without_stream_flying",
            "1.16.2",
            lambda: cl.OffboardControlCpp(send_stream=False),
            "ros2",
            5.0,
            takeoff=True,
            after_s=3.0,
        ),
        Scenario(
            "hazard_mavros_stall_mid_air",
            "1.14.4",
            lambda: cl.MavrosOffbNode(stall=(25.0, 26.5)),
            "mavros",
            32.0,
            after_s=0.3,
        ),
        Scenario(
            "hazard_rover_trajectory_yaw",
            "1.17.0",
            lambda: cl.RoverSpeedAttitude(trajectory_yaw=True),
            "ros2",
            10.0,
            after_s=0.3,
        ),
    )
}


# ---------------------------------------------------------------------------------------------
# The client's messages, as PX4 receives them over MAVLink


class MavlinkSender:
    """Sends PX4 the MAVLink equivalent of each cycle's messages (``clients.py``)."""

    def __init__(self, link: Link) -> None:
        self.link = link
        self.last_setpoint: dict[str, Any] | None = None

    def send_cycle(self, pubs: list[cl.Pub], view: VehicleView) -> None:
        for i, pub in enumerate(pubs):
            if pub.topic.endswith(cl.OCM):
                same_cycle = [p for p in pubs[i + 1 :] if p.topic.endswith(cl.TRAJ)]
                self._keepalive(pub, same_cycle[0] if same_cycle else None, pubs, view)
            elif pub.topic.endswith(cl.CMD):
                f = pub.fields
                self.link.send(
                    self.link.conn.mav.command_long_encode(
                        self.link.target_system,
                        1,
                        int(f["command"]),
                        0,
                        float(f["param1"]),
                        float(f["param2"]),
                        0,
                        0,
                        0,
                        0,
                        0,
                    )
                )
            elif pub.topic.endswith(cl.GOTO):
                f = pub.fields
                mask = 0b1_1111_1000 | cl.IGNORE_YAW_RATE  # position (+ yaw)
                if not f["flag_control_heading"]:
                    mask |= cl.IGNORE_YAW
                x, y, z = f["position"]
                self._local(mask, {"x": x, "y": y, "z": z, "yaw": f["heading"]})
            elif pub.topic == cl.MAVROS_POSE:
                self._mavros_pose(pub)
            elif pub.topic == cl.MAVROS_SET_MODE:
                base = 1 | (128 if view.armed else 0)  # CUSTOM_MODE_ENABLED (+ SAFETY_ARMED)
                self.link.send(
                    self.link.conn.mav.set_mode_encode(self.link.target_system, base, 6 << 16)
                )
            elif pub.topic == cl.MAVROS_ARMING:
                self.link.send(
                    self.link.conn.mav.command_long_encode(
                        self.link.target_system, 1, 400, 0, 1.0, 0, 0, 0, 0, 0, 0
                    )
                )

    def _keepalive(
        self, ocm: cl.Pub, traj: cl.Pub | None, pubs: list[cl.Pub], view: VehicleView
    ) -> None:
        flags = ocm.fields
        if flags["attitude"] and not (flags["position"] or flags["velocity"]):
            yaw = float(traj.fields["yaw"]) if traj is not None else 0.0
            q = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
            self.link.send(
                self.link.conn.mav.set_attitude_target_encode(
                    0, self.link.target_system, 1, 0b0000_0111, q, 0, 0, 0, 0.0
                )
            )
            return
        if traj is not None:
            self.last_setpoint = traj.fields
        speed = [p for p in pubs if p.topic.endswith(cl.ROVER_SPEED)]
        attitude = [p for p in pubs if p.topic.endswith(cl.ROVER_ATT)]
        if speed and attitude:
            # the bundles cannot run a rover (README.md): the multicopter that answers gets the
            # velocity flag the combination declares with speed 0, so that it stays on the ground
            yaw = float(attitude[0].fields["yaw_setpoint"])
            self._local(0b1001_1100_0111, {"yaw": yaw})  # velocity + yaw
            return
        fields = self.last_setpoint
        if fields is None:
            # OCM with no setpoint yet: PX4 ignores setpoint content outside OFFBOARD, and holds
            # where it is when it has none; the driver sends that hold
            fields = cl.trajectory(0, (view.x, view.y, view.z), yaw=math.nan).fields
            fields["yawspeed"] = math.nan
        mask, values = cl.trajectory_mask(fields)
        self._local(mask, values)

    def hold(self, view: VehicleView) -> None:
        """A keep-alive holding the current position: not the client's, the driver's (PX4 must
        see an offboard stream before OFFBOARD is selected; an external mode needs none)."""
        self._local(
            0b1_1111_1000 | cl.IGNORE_YAW | cl.IGNORE_YAW_RATE,
            {"x": view.x, "y": view.y, "z": view.z},
        )

    def _mavros_pose(self, pub: cl.Pub) -> None:
        # MAVROS 1 setpoint_position: ENU -> NED (y, x, -z); the zero quaternion the example
        # leaves becomes the identity rotation (Eigen's toRotationMatrix), i.e. yaw 0 in ENU,
        # pi/2 in NED; type_mask 0x9F8 (position + yaw); time_boot_ms from the zero stamp
        x, y, z = pub.fields["position"]
        self._local(0x9F8, {"x": y, "y": x, "z": -z, "yaw": math.pi / 2})

    def _local(self, mask: int, values: dict[str, float]) -> None:
        v = {
            name: 0.0
            for name in ("x", "y", "z", "vx", "vy", "vz", "afx", "afy", "afz", "yaw", "yaw_rate")
        }
        v.update(values)
        self.link.send(
            self.link.conn.mav.set_position_target_local_ned_encode(
                0,
                self.link.target_system,
                1,
                1,
                mask,
                v["x"],
                v["y"],
                v["z"],
                v["vx"],
                v["vy"],
                v["vz"],
                v["afx"],
                v["afy"],
                v["afz"],
                v["yaw"],
                v["yaw_rate"],
            )
        )


# ---------------------------------------------------------------------------------------------
# Ground-station steps (a pilot with QGroundControl)


def gcs_command(link: Link, command: int, *params: float) -> None:
    p = [*params, *([0.0] * (7 - len(params)))]
    msg = link.conn.mav.command_long_encode(link.target_system, 1, command, 0, *p)
    link.gcs.seq = (link.gcs.seq + 1) % 256
    link.send(msg, gcs=True)


def gcs_step(link: Link, step: str) -> None:
    if step == "offboard":
        gcs_command(link, 176, 1, 6)
    elif step == "hold":
        gcs_command(link, 176, 1, 4, 3)
    elif step == "land":
        gcs_command(link, 21)
    elif step == "goto_mode":
        # the external mode cannot be registered here (no ROS 2 bridge): the pilot selects
        # OFFBOARD instead, and the client's goto setpoints are flown as position setpoints,
        # after a hold stream from the driver (MavlinkSender.hold)
        gcs_command(link, 176, 1, 6)
    else:
        raise ValueError(step)


def takeoff(link: Link) -> None:
    """QGroundControl's Takeoff: NAV_TAKEOFF (altitude from MIS_TAKEOFF_ALT), then arm; wait
    until PX4 reports AUTO_TAKEOFF and then holds at the top (AUTO_LOITER, in the air)."""
    gcs_command(link, 22, 0, 0, 0, math.nan, math.nan, math.nan, math.nan)
    link.sleep_until(link.now_us() + 300_000)
    gcs_command(link, 400, 1)
    view = link.view
    link.wait_for("armed", lambda: view.armed, 10)
    link.wait_for(
        "AUTO_TAKEOFF",
        lambda: (view.main_mode, view.sub_mode) == (cl.AUTO_MAIN, cl.TAKEOFF_SUB),
        10,
    )
    link.wait_for(
        "the end of the takeoff",
        lambda: (
            (view.main_mode, view.sub_mode) == (cl.AUTO_MAIN, cl.LOITER_SUB)
            and view.landed_state == 2
        ),  # MAV_LANDED_STATE_IN_AIR
        60,
    )
    link.sleep_until(link.now_us() + 2_000_000)


# ---------------------------------------------------------------------------------------------


def seed_parameters(release: str, instance: int) -> Path:
    """A parameters.bson with SDLOG_MODE 2 (log from boot) for 1.14 and 1.15, which do not
    take PX4_PARAM_*: set once over MAVLink and saved by PX4 in its working folder."""
    seed = WORK / f"seed-{release}.bson"
    if seed.exists():
        return seed
    workdir = WORK / f"seed-{release}"
    shutil.rmtree(workdir, ignore_errors=True)
    with px4(release, instance, workdir, {}) as run:
        conn: Any = mavutil.mavlink_connection(f"udpin:127.0.0.1:{14540 + instance}")
        conn.wait_heartbeat(timeout=30)
        time.sleep(3)
        # PX4 reads PARAM_SET values bytewise: an INT32 travels in the float's bits
        as_float = struct.unpack("<f", struct.pack("<i", 2))[0]
        for _ in range(10):
            conn.mav.param_set_send(instance + 1, 1, b"SDLOG_MODE", as_float, 6)
            msg = conn.recv_match(type="PARAM_VALUE", blocking=True, timeout=2)
            if msg is not None and msg.param_id == "SDLOG_MODE":
                value = struct.unpack("<i", struct.pack("<f", msg.param_value))[0]
                if value == 2:
                    break
        else:
            raise RuntimeError(f"PX4 {release} did not take SDLOG_MODE 2")
        time.sleep(2)
        conn.close()
        run.stop()
    shutil.copy(workdir / "parameters.bson", seed)
    return seed


def run_scenario(scenario: Scenario, instance: int) -> None:
    RUNS.mkdir(exist_ok=True)
    workdir = WORK / scenario.name
    shutil.rmtree(workdir, ignore_errors=True)
    env = {"PX4_SIM_MODEL": scenario.model}
    if scenario.release.startswith(("1.14", "1.15")):
        env["SEED_PARAMS"] = str(seed_parameters(scenario.release, instance))
    else:
        env["PX4_PARAM_SDLOG_MODE"] = "2"
    tlog = RUNS / f"{scenario.name}.tlog"
    pubs: list[cl.Pub] = []
    late = 0
    marks: dict[str, int] = {}
    gcs_done: list[tuple[int, str]] = []
    with px4(scenario.release, instance, workdir, env) as run:
        link = Link(
            instance,
            tlog,
            MAVROS_SYSTEM,
            MAVROS_COMPONENT,
            scenario.transport == "ros2",
            scenario.local_position_hz,
        )
        try:
            link.wait_for("a clock", lambda: link.clock.ready, 60)
            link.wait_for("pre-arm checks", lambda: link.view.prearm_ok, 120)
            link.sleep_until(link.now_us() + 3_000_000)
            marks["record_start"] = link.now_us()
            if scenario.takeoff:
                link.sleep_until(link.now_us() + 1_000_000)
                takeoff(link)
            client = scenario.client()
            sender = MavlinkSender(link)
            next_heartbeat = link.now_us()
            start = marks["client_start"] = link.now_us() + 1_000_000
            if not scenario.takeoff:
                marks["record_start"] = start - 1_000_000
            link.sleep_until(start)
            steps = sorted(scenario.gcs)
            tick = start
            end = start + round(scenario.duration_s * 1e6)
            while tick < end and not client.done:
                link.sleep_until(tick)
                now = link.now_us()
                late = max(late, now - tick)
                while steps and now >= start + steps[0][0] * 1e6:
                    step = steps.pop(0)[1]
                    gcs_step(link, step)
                    gcs_done.append((link.now_us(), step))
                if scenario.transport == "mavros" and now >= next_heartbeat:
                    # MAVROS's own HEARTBEAT, 1 Hz: onboard controller, MANUAL_ARMED
                    link.send(link.conn.mav.heartbeat_encode(18, 8, 192, 0, 4))
                    next_heartbeat += 1_000_000
                cycle = client.cycle(now, link.view)
                if isinstance(client, cl.GotoMode) and not cycle:
                    sender.hold(link.view)  # see gcs_step("goto_mode")
                sender.send_cycle(cycle, link.view)
                pubs.extend(cycle)
                # a ROS timer that fell behind skips the periods it missed (rcl), no burst
                tick += client.period_us
                while tick <= link.now_us():
                    tick += client.period_us
            marks["client_end"] = link.now_us()
            for _, step in steps:  # steps due at the very end
                gcs_step(link, step)
                gcs_done.append((link.now_us(), step))
            link.sleep_until(link.now_us() + round(scenario.after_s * 1e6))
            marks["record_end"] = link.now_us()
            texts = link.statustexts
        finally:
            link.close()
        ulog = run.stop()
    print(f"{scenario.name}: latest cycle {late / 1000:.1f} ms after its tick", flush=True)
    if late > MAX_LATE_US:
        raise LateRun(f"{scenario.name}: a client cycle ran {late / 1000:.0f} ms late")
    cut_ulog(ulog, RUNS / f"{scenario.name}.ulg", scenario.local_position_hz)
    record = {
        "scenario": scenario.name,
        "release": scenario.release,
        "model": scenario.model,
        "transport": scenario.transport,
        "px4_system": instance + 1,
        "marks_us": marks,
        "gcs_us": gcs_done,
        "statustexts": texts,
        "pubs": [p.to_json() for p in pubs],
    }
    with gzip.open(RUNS / f"{scenario.name}.client.json.gz", "wt", encoding="utf-8") as fh:
        fh.write(json.dumps(record, separators=(",", ":")) + "\n")


class LateRun(RuntimeError):
    """The driver could not keep the client's timing (the machine was busy): run it again."""


def cut_ulog(source: Path, target: Path, local_position_hz: float) -> None:
    """Keep the recordings' topics, vehicle_local_position at ``local_position_hz``."""
    log = ULog(str(source), message_name_filter_list=list(ULOG_TOPICS))
    for data in log.data_list:
        if data.name != "vehicle_local_position":
            continue
        stamps = data.data["timestamp"]
        keep = [0]
        for i in range(1, len(stamps)):
            if stamps[i] - stamps[keep[-1]] >= 1e6 / local_position_hz - 2000:
                keep.append(i)
        data.data = {name: values[keep] for name, values in data.data.items()}
    # the formats of the kept topics and the types they nest; not PX4's event metadata and
    # preflight perf counters (about 55 kB of diagnostics per log)
    needed = {data.name for data in log.data_list}
    pending = list(needed)
    while pending:
        for member in log.message_formats[pending.pop()].fields:
            base = member[0]
            if base in log.message_formats and base not in needed:
                needed.add(base)
                pending.append(base)
    log._message_formats = {k: v for k, v in log.message_formats.items() if k in needed}
    for key in ("metadata_events", "perf_counter_preflight"):
        log.msg_info_multiple_dict.pop(key, None)
    log.write_ulog(str(target))


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="+", help="scenario names, or 'all'")
    parser.add_argument("--instance", type=int, default=4, choices=(4, 5))
    args = parser.parse_args(argv)
    names = list(SCENARIOS) if args.names == ["all"] else args.names
    # the driver sleeps between cycles and needs little CPU, but a busy machine can hold it
    # back for a few hundred ms; the lowest real-time priority keeps its timing
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))
    except (OSError, AttributeError):
        os.nice(-10)
    for name in names:
        for attempt in range(1, 6):
            started = time.monotonic()
            try:
                run_scenario(SCENARIOS[name], args.instance)
            except LateRun as exc:
                print(f"{exc}; attempt {attempt}, again", flush=True)
                continue
            print(f"{name}: {time.monotonic() - started:.0f} s", flush=True)
            break
        else:
            print(f"{name}: no run kept its timing", flush=True)
            return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
