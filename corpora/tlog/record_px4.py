"""Record real PX4 tlogs: a pymavlink client flies a short offboard flight on PX4 SITL.

Run ``.venv/bin/python corpora/tlog/record_px4.py SCENARIO [--bundle DIR] [--instance N]``
with a bundle from ``../shared/px4-sitl`` (see its README). PX4 is started headless in a new
folder under /tmp with ``run-px4.sh``; two pymavlink connections talk to it, and each writes its
own log opened with pymavlink's ``setup_logfile``, one ``[8-byte big-endian µs][packet]``
record per message received (written as ``mavfile.recv_msg`` writes it: pymavlink's UDP
connection skips that step) or sent (through pymavlink's send callback):

* ``NAME.onboard.tlog``: the onboard/API link (PX4 listens on 14580+N): what a companion
  computer running MAVSDK or MAVROS exchanges with PX4, setpoints and commands included;
* ``NAME.gcs.tlog``: the GCS link (18570+N), what QGroundControl logs: PX4's telemetry, modes,
  acks and STATUSTEXT, but no setpoint (PX4 does not forward messages addressed to itself).

Both clients connect to PX4's listening port from a port of their own (PX4 answers to the
address it last heard from), so nothing binds the fixed ports other PX4 instances send to.
``trim`` then cuts the onboard log to the message types named in ``KEPT`` (the telemetry PX4
streams at 50-100 Hz on that link would take megabytes) through pymavlink's reader, writing each
kept message's own packet bytes back unchanged. PX4's own ULog of the flight becomes
``NAME.ulg`` (``cut_ulog``: pyulog keeps the topics fuzzoff's lint reads, with
``vehicle_local_position`` at 10 Hz, and writes them back), so one flight has three recordings.

Scenarios:

* ``clean``: setpoints at 20 Hz for 2 s, switch to OFFBOARD, arm, climb to 3 m, hold, fly 3 m
  north with a velocity setpoint part of the way, then AUTO_LAND until disarmed.
* ``loss``: the same climb, then the setpoints stop in OFFBOARD with no manual control: PX4
  declares the offboard signal lost and runs its failsafe (1.17: Return).
"""

from __future__ import annotations

import argparse
import os
import signal
import struct
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil
from pymavlink.dialects.v20 import development as mavlink

HERE = Path(__file__).resolve().parent
SHARED = HERE.parents[2] / "shared" / "px4-sitl"

COMPANION = (245, 191)  # MAV_COMP_ID_ONBOARD_COMPUTER, a sysid of its own as MAVSDK uses
GCS = (255, 190)  # QGroundControl's ids
OFFBOARD_MAIN = 6
AUTO_MAIN, LAND_SUB = 4, 6
PREARM_BIT = 1 << 28  # MAV_SYS_STATUS_PREARM_CHECK
POSITION_MASK = 0b1001_1111_1000  # x, y, z and yaw
VELOCITY_MASK = 0b1001_1100_0111  # vx, vy, vz and yaw

KEPT = frozenset(
    {
        "HEARTBEAT",
        "SYS_STATUS",
        "COMMAND_LONG",
        "COMMAND_INT",
        "COMMAND_ACK",
        "SET_MODE",
        "SET_POSITION_TARGET_LOCAL_NED",
        "SET_POSITION_TARGET_GLOBAL_INT",
        "SET_ATTITUDE_TARGET",
        "POSITION_TARGET_LOCAL_NED",
        "LOCAL_POSITION_NED",
        "EXTENDED_SYS_STATE",
        "AUTOPILOT_VERSION",
        "PARAM_VALUE",
        "STATUSTEXT",
        "CURRENT_MODE",
        "SYSTEM_TIME",
        "TIMESYNC",
        "GNSS_INTEGRITY",
    }
)
"""Message types kept by ``trim``, with every packet of an id pymavlink's ``development``
dialect does not know (``UNKNOWN_<id>``: PX4 sends some at every connection)."""


def log_message(conn: Any, msg: Any) -> None:
    """One tlog record for ``msg`` in ``conn``'s log, as pymavlink's ``mavfile.recv_msg``
    writes it (its UDP connection's ``recv_msg`` does not log, so received messages come here)."""
    if conn.logfile is not None and msg.get_type() != "BAD_DATA":
        usec = int(time.time() * 1.0e6) & ~3
        conn.logfile.write(struct.pack(">Q", usec) + msg.get_msgbuf())


def log_sent(conn: Any) -> None:
    """Write each message ``conn`` sends into its log too."""
    conn.mav.set_send_callback(lambda msg: log_message(conn, msg))


class Flight:
    def __init__(self, instance: int, out: Path, name: str) -> None:
        self.t0 = time.monotonic()
        sysid = instance + 1
        self.target = sysid
        self.onboard = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{14580 + instance}",
            source_system=COMPANION[0],
            source_component=COMPANION[1],
            dialect="development",
        )
        self.gcs = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{18570 + instance}",
            source_system=GCS[0],
            source_component=GCS[1],
            dialect="development",
        )
        self.paths = (out / f"{name}.onboard.full.tlog", out / f"{name}.gcs.tlog")
        self.mode: tuple[int, int] = (0, 0)
        self.armed = False
        self.acks: list[Any] = []
        self.healthy = False
        self.next_hb = 0.0
        self.z = 0.0

    def ms(self) -> int:
        return int((time.monotonic() - self.t0) * 1000)

    def start_logs(self) -> None:
        for conn, path in zip((self.onboard, self.gcs), self.paths, strict=True):
            conn.setup_logfile(str(path))
            log_sent(conn)
        for conn in (self.onboard, self.gcs):  # as QGC and MAVSDK do at connection
            conn.mav.command_long_send(self.target, 1, 512, 0, 148, 0, 0, 0, 0, 0, 0)

    def pump(
        self, seconds: float, each: Callable[[], None] | None = None, period: float = 0.05
    ) -> None:
        """Run for ``seconds``: heartbeats at 1 Hz on both links, ``each`` every ``period``."""
        end = time.monotonic() + seconds
        next_each = time.monotonic()
        while (now := time.monotonic()) < end:
            if now >= self.next_hb:
                self.next_hb = now + 1.0
                self.onboard.mav.heartbeat_send(18, 8, 0, 0, 4)  # onboard controller
                self.gcs.mav.heartbeat_send(6, 8, 0, 0, 4)  # GCS
            if each is not None and now >= next_each:
                next_each += period
                each()
            for conn in (self.onboard, self.gcs):
                while (msg := conn.recv_msg()) is not None:
                    log_message(conn, msg)
                    self.seen(conn, msg)
            time.sleep(0.002)

    def seen(self, conn: Any, msg: Any) -> None:
        if msg.get_srcSystem() != self.target or msg.get_srcComponent() != 1:
            return
        kind = msg.get_type()
        if conn is not self.onboard:
            return
        if kind == "HEARTBEAT":
            main, sub = (msg.custom_mode >> 16) & 0xFF, (msg.custom_mode >> 24) & 0xFF
            self.mode = (main, sub)
            self.armed = bool(msg.base_mode & 128)
        elif kind == "SYS_STATUS":
            self.healthy = bool(msg.onboard_control_sensors_health & PREARM_BIT)
        elif kind == "COMMAND_ACK":
            self.acks.append(msg)
        elif kind == "LOCAL_POSITION_NED":
            self.z = msg.z

    def wait(
        self, what: Callable[[], bool], timeout: float, each: Callable[[], None] | None = None
    ) -> None:
        end = time.monotonic() + timeout
        while not what():
            if time.monotonic() > end:
                raise SystemExit("timed out waiting for PX4")
            self.pump(0.1, each)

    def command(self, command: int, *params: float) -> None:
        p = [*params, 0, 0, 0, 0, 0, 0, 0][:7]
        self.onboard.mav.command_long_send(self.target, 1, command, 0, *p)

    def position(self, x: float, y: float, z: float) -> Callable[[], None]:
        def send() -> None:
            self.onboard.mav.set_position_target_local_ned_send(
                self.ms(), self.target, 1, 1, POSITION_MASK, x, y, z, 0, 0, 0, 0, 0, 0, 0, 0
            )

        return send

    def velocity(self, vx: float, vy: float, vz: float) -> Callable[[], None]:
        def send() -> None:
            self.onboard.mav.set_position_target_local_ned_send(
                self.ms(), self.target, 1, 1, VELOCITY_MASK, 0, 0, 0, vx, vy, vz, 0, 0, 0, 0, 0
            )

        return send

    def arm(self, each: Callable[[], None]) -> None:
        """Retry the arm command each second until PX4 accepts it (pre-flight checks settle)."""
        for _ in range(60):
            self.acks.clear()
            self.command(400, 1)
            self.pump(1.0, each)
            if any(a.command == 400 and a.result == 0 for a in self.acks) or self.armed:
                return
        raise SystemExit("PX4 never accepted arming")

    def close(self) -> None:
        for conn in (self.onboard, self.gcs):
            if conn.logfile is not None:
                conn.logfile.close()
                conn.logfile = None
            conn.close()


def fly(flight: Flight, scenario: str) -> None:
    flight.pump(2.0)  # let PX4 hear both clients
    flight.wait(lambda: flight.healthy, 90)
    flight.start_logs()
    flight.pump(2.0)
    hover = flight.position(0.0, 0.0, -3.0)
    flight.pump(2.0, hover)  # the docs' second of stream before the switch, twice over
    flight.command(176, 1, OFFBOARD_MAIN)
    flight.pump(0.5, hover)
    flight.arm(hover)
    flight.wait(lambda: flight.z < -2.7, 30, hover)
    flight.pump(3.0, hover)
    if scenario == "loss":
        flight.pump(12.0)  # no setpoint, no manual control: PX4's failsafe decides
        flight.wait(lambda: not flight.armed, 90)
        flight.pump(1.0)
        return
    flight.pump(2.0, flight.velocity(1.0, 0.0, 0.0))
    flight.pump(4.0, flight.position(3.0, 0.0, -3.0))
    flight.command(176, 1, AUTO_MAIN, LAND_SUB)
    flight.pump(1.0, flight.position(3.0, 0.0, -3.0))  # a client stops shortly after the switch
    flight.wait(lambda: not flight.armed, 60)
    flight.pump(1.0)


def trim(full: Path, target: Path) -> tuple[int, int]:
    """Keep the ``KEPT`` types and every unknown id; returns (kept, dropped) message counts."""
    log = mavutil.mavlink_connection(str(full), dialect="development")
    kept = dropped = 0
    with target.open("wb") as out:
        while (msg := log.recv_msg()) is not None:
            kind = msg.get_type()
            if kind == "BAD_DATA":
                continue
            if kind in KEPT or isinstance(msg, mavlink.MAVLink_unknown):
                out.write(struct.pack(">Q", round(msg._timestamp * 1e6)) + msg.get_msgbuf())
                kept += 1
            else:
                dropped += 1
    return kept, dropped


def cut_ulog(source: Path, target: Path) -> None:
    """PX4's ULog cut to the topics fuzzoff's lint reads (header, info, parameters, formats and
    logged messages kept), ``vehicle_local_position`` thinned from ~125 Hz to 10 Hz."""
    from pyulog import ULog

    from fuzzoff.formats.ulog.reader import LOADED_TOPICS

    log = ULog(str(source), message_name_filter_list=list(LOADED_TOPICS))
    for data in log.data_list:
        if data.name == "vehicle_local_position":
            stamps = data.data["timestamp"]
            keep = [0]
            for i in range(1, len(stamps)):
                if stamps[i] - stamps[keep[-1]] >= 98_000:
                    keep.append(i)
            data.data = {name: values[keep] for name, values in data.data.items()}
    log.write_ulog(str(target))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", choices=("clean", "loss"))
    parser.add_argument("--bundle", type=Path, default=SHARED / "1.16.2")
    parser.add_argument("--instance", type=int, default=6)
    parser.add_argument("--out", type=Path, default=HERE)
    args = parser.parse_args()
    version = args.bundle / "VERSION"
    release = version.read_text().split()[1] if version.exists() else args.bundle.name
    name = f"px4_{args.bundle.name.replace('.', '_')}_{args.scenario}"
    work = Path(tempfile.mkdtemp(prefix=f"fuzzoff-readers-px4-{args.instance}-"))
    env = os.environ | {"PX4_INSTANCE": str(args.instance)}
    px4 = subprocess.Popen(
        [str(SHARED / "run-px4.sh"), str(args.bundle), str(work / "px4")],
        env=env,
        stdout=(work / "px4.out").open("w"),
        stderr=subprocess.STDOUT,
    )
    flight = Flight(args.instance, work, name)
    try:
        fly(flight, args.scenario)
    finally:
        flight.close()
        px4.send_signal(signal.SIGINT)
        px4.wait(timeout=30)
    onboard_full, gcs = flight.paths
    kept, dropped = trim(onboard_full, args.out / f"{name}.onboard.tlog")
    gcs_target = args.out / f"{name}.gcs.tlog"
    gcs_target.write_bytes(gcs.read_bytes())
    ulogs = sorted((work / "px4" / "log").rglob("*.ulg"))
    if ulogs:
        cut_ulog(ulogs[-1], args.out / f"{name}.ulg")
    print(f"PX4 {release}: {work}; onboard kept {kept}, dropped {dropped}; ulogs {ulogs}")


if __name__ == "__main__":
    sys.exit(main())
