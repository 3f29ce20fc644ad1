"""Drive a PX4 SITL bundle over MAVLink at PX4's own pace, and keep a tlog of the exchange.

The SITL bundles in ``../shared/px4-sitl`` have no ROS 2 bridge, so an example client's stream
reaches PX4 over its MAVLink API link instead (``clients.py`` says what each ROS message
becomes). PX4 runs in lockstep with its simulator at 0.8-1.0 of real time, so the client is paced
by PX4's clock, not the wall clock: the newest ``ATTITUDE.time_boot_ms`` (about 100 Hz),
extrapolated at the measured speed. A 10 Hz client is then 10 Hz in the ULog, as it would be on a
real vehicle whose clock runs at the same rate as the companion's.

The tlog holds what the driver sent and the vehicle messages it listened to (HEARTBEAT,
COMMAND_ACK, STATUSTEXT, EXTENDED_SYS_STATE, SYS_STATUS, and LOCAL_POSITION_NED at the rate the
run keeps the ULog's ``vehicle_local_position``), each record stamped with PX4's clock
(``EPOCH_US`` + PX4 boot time in microseconds) so that it lines up with the ULog.
"""

from __future__ import annotations

import os
import signal
import struct
import subprocess
import time
from collections import deque
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil

SITL = Path(__file__).resolve().parents[3] / "shared" / "px4-sitl"
"""``/work/shared/px4-sitl`` seen from ``/work/<worktree>/corpora/examples``."""

EPOCH_US = 1_767_225_600_000_000
"""2026-01-01 00:00:00 UTC: the wall-clock time given to PX4's boot in the tlogs."""

LISTENED = frozenset({"HEARTBEAT", "COMMAND_ACK", "STATUSTEXT", "EXTENDED_SYS_STATE", "SYS_STATUS"})
"""Vehicle messages kept in the tlog (the rest of PX4's stream is only read for the clock)."""

PREARM_OK = 0x10000000
"""MAV_SYS_STATUS_PREARM_CHECK in SYS_STATUS.onboard_control_sensors_health."""

STATUS_AFTER_ACK_US = 20_000
"""PX4 published vehicle_status 0-12 ms after Commander's ack in these runs; DDS and the
bridge add a few ms, the driver's clock may lag PX4's by a few more."""

AUTO_LAND = 4 << 16 | 6 << 24
AUTO_TAKEOFF = 4 << 16 | 2 << 24
"""HEARTBEAT custom modes of AUTO_LAND and AUTO_TAKEOFF."""

GCS_SYSTEM, GCS_COMPONENT = 255, 190
"""QGroundControl's ids: commands a user gives from the ground station come from here."""


@dataclass
class VehicleView:
    """What a client knows of the vehicle: the newest HEARTBEAT and LOCAL_POSITION_NED."""

    custom_mode: int = 0
    base_mode: int = 0
    z: float = 0.0
    vz: float = 0.0
    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    landed_state: int = 0
    prearm_ok: bool = False

    @property
    def armed(self) -> bool:
        return bool(self.base_mode & 128)

    @property
    def main_mode(self) -> int:
        return (self.custom_mode >> 16) & 0xFF

    @property
    def sub_mode(self) -> int:
        return (self.custom_mode >> 24) & 0xFF


MAX_AHEAD_US = 15_000
"""ATTITUDE comes every 10 ms of PX4 time; no sample for longer means PX4 is not running."""


class Px4Clock:
    """PX4's boot time in µs, from the newest ``time_boot_ms`` and the wall clock since."""

    def __init__(self) -> None:
        self.anchors: deque[tuple[float, int]] = deque(maxlen=64)
        """One (wall, PX4) sample every 0.1 s or more, for the speed over the last seconds."""
        self.newest: tuple[float, int] | None = None
        self.speed = 0.9
        self.last = 0

    def observe(self, boot_ms: int) -> None:
        wall = time.monotonic()
        px4_us = boot_ms * 1000
        if self.newest is not None and px4_us <= self.newest[1]:
            return
        self.newest = (wall, px4_us)
        if not self.anchors or wall - self.anchors[-1][0] >= 0.1:
            self.anchors.append((wall, px4_us))
            first_wall, first_us = self.anchors[0]
            if wall - first_wall > 1.0:
                self.speed = (px4_us - first_us) / 1e6 / (wall - first_wall)

    @property
    def ready(self) -> bool:
        return len(self.anchors) > 10

    def now_us(self) -> int:
        """Never more than ``MAX_AHEAD_US`` past the newest sample: when PX4 stalls (the machine
        is busy and lockstep holds the simulation), the client waits with it."""
        assert self.newest is not None
        wall, px4_us = self.newest
        ahead = min(round((time.monotonic() - wall) * self.speed * 1e6), MAX_AHEAD_US)
        self.last = max(self.last, px4_us + ahead)
        return self.last


class Link:
    """The MAVLink API link of one PX4 instance (PX4 sends to 14540+N, listens on 14580+N)."""

    def __init__(
        self,
        instance: int,
        tlog: Path,
        system: int,
        component: int,
        status_from_acks: bool,
        position_hz: float = 0.0,
    ) -> None:
        self.target_system = instance + 1
        self.target_component = 1
        self.conn: Any = mavutil.mavlink_connection(
            f"udpin:127.0.0.1:{14540 + instance}",
            source_system=system,
            source_component=component,
        )
        self.gcs: Any = mavutil.mavlink.MAVLink(
            None, srcSystem=GCS_SYSTEM, srcComponent=GCS_COMPONENT
        )
        self.gcs.robust_parsing = True
        self.clock = Px4Clock()
        self.view = VehicleView()
        self.tlog: BinaryIO = tlog.open("wb")
        self.statustexts: list[tuple[int, str]] = []
        self.status_from_acks = status_from_acks
        """ROS 2 clients (vehicle_status); not MAVROS clients, whose state is the HEARTBEAT."""
        self.requested_mode: dict[int, tuple[int, int]] = {}
        """command -> (custom_mode before, custom_mode it asks for)."""
        self.requested_arm: bool | None = None
        self.pending: list[tuple[int, str, int | bool]] = []
        self.position_period_us = round(1e6 / position_hz) if position_hz else 0
        """LOCAL_POSITION_NED kept in the tlog at most this often (0: none), as the ULog's
        ``vehicle_local_position`` is cut (``runs.cut_ulog``), to keep files under 1 MB."""
        self.position_due = 0

    # -- receiving
    def pump(self, timeout: float = 0.0) -> None:
        """Read every message waiting (waiting up to ``timeout`` for the first)."""
        deadline = time.monotonic() + timeout
        while True:
            self._apply_pending()
            msg = self.conn.recv_match(blocking=False)
            if msg is None:
                if time.monotonic() >= deadline:
                    return
                time.sleep(0.0005)
                continue
            self._take(msg)

    def _take(self, msg: Any) -> None:
        kind = msg.get_type()
        if msg.get_srcSystem() != self.target_system:
            return
        if kind == "ATTITUDE":
            self.clock.observe(msg.time_boot_ms)
            self.view.heading = msg.yaw
            return
        if kind == "LOCAL_POSITION_NED":
            self.view.x, self.view.y, self.view.z, self.view.vz = msg.x, msg.y, msg.z, msg.vz
            if self.position_period_us and self.clock.ready:
                now = self.clock.now_us()
                if now >= self.position_due:
                    self._record(now, msg.get_msgbuf())
                    self.position_due = now + self.position_period_us - 2000
            return
        if kind not in LISTENED or not self.clock.ready:
            return
        now = self.clock.now_us()
        self._record(now, msg.get_msgbuf())
        if kind == "HEARTBEAT" and msg.get_srcComponent() == 1:
            self.view.custom_mode = msg.custom_mode
            self.view.base_mode = msg.base_mode
        elif kind == "COMMAND_ACK":
            if self.status_from_acks:
                self._acked(msg.command, msg.result, now)
        elif kind == "EXTENDED_SYS_STATE":
            self.view.landed_state = msg.landed_state
        elif kind == "SYS_STATUS":
            self.view.prearm_ok = bool(msg.onboard_control_sensors_health & PREARM_OK)
        elif kind == "STATUSTEXT":
            self.statustexts.append((now, msg.text))

    def _acked(self, command: int, result: int, now: int) -> None:
        """A ROS 2 client reads mode and arming from vehicle_status, which PX4 publishes about
        10 ms after it acks the command that changed them; over MAVLink the HEARTBEAT comes at
        1 Hz. So an acked switch, land, takeoff or arm updates the view ``STATUS_AFTER_ACK_US``
        after the ack (the last ack for a command wins: 1.16 and 1.17 ack a switch twice).
        Changes PX4 makes by itself (a failsafe, the end of a takeoff, a disarm after landing)
        reach the view with the next HEARTBEAT."""
        due = now + STATUS_AFTER_ACK_US
        if command in self.requested_mode:
            before, requested = self.requested_mode[command]
            self._pend(due, "custom_mode", requested if result == 0 else before)
        elif command == 400 and result == 0 and self.requested_arm is not None:
            self._pend(due, "armed", self.requested_arm)

    def _pend(self, due: int, name: str, value: int | bool) -> None:
        """A later ack of the same change replaces the one still waiting (the first of the two
        acks of a 1.16 switch is the receiver's; vehicle_status follows Commander's)."""
        self.pending = [p for p in self.pending if p[1] != name]
        self.pending.append((due, name, value))

    def _apply_pending(self) -> None:
        if not self.pending or not self.clock.ready:
            return
        now = self.clock.now_us()
        while self.pending and self.pending[0][0] <= now:
            _, name, value = self.pending.pop(0)
            if name == "custom_mode":
                self.view.custom_mode = int(value)
            else:
                self.view.base_mode = (self.view.base_mode & ~128) | (128 if value else 0)

    def _record(self, px4_us: int, packet: bytes) -> None:
        self.tlog.write(struct.pack(">Q", EPOCH_US + px4_us) + bytes(packet))

    # -- time
    def now_us(self) -> int:
        return self.clock.now_us()

    def sleep_until(self, px4_us: int) -> None:
        """Listen until PX4's clock reaches ``px4_us``."""
        while self.clock.now_us() < px4_us:
            remaining = (px4_us - self.clock.now_us()) / 1e6 / max(self.clock.speed, 0.1)
            self.pump(timeout=min(max(remaining - 0.002, 0.0), 0.01))

    def wait_for(self, what: str, test: Any, timeout_s: float) -> None:
        deadline = time.monotonic() + timeout_s
        while not test():
            if time.monotonic() > deadline:
                raise TimeoutError(f"PX4 did not get {what} within {timeout_s:g} s")
            self.pump(timeout=0.05)

    # -- sending
    def send(self, msg: Any, *, gcs: bool = False) -> int:
        """Send ``msg`` (from the ground station's ids if ``gcs``); returns PX4's time."""
        now = self.clock.now_us()
        self._note_request(msg)
        if gcs:
            packet = msg.pack(self.gcs)
            self.conn.write(packet)
        else:
            self.conn.mav.send(msg)
            packet = msg.get_msgbuf()
        self._record(now, packet)
        return now

    def _note_request(self, msg: Any) -> None:
        kind = msg.get_type()
        before = self.view.custom_mode
        if kind == "COMMAND_LONG" and msg.command == 176:
            custom = int(msg.param2) << 16 | int(msg.param3) << 24
            self.requested_mode[176] = (before, custom)
        elif kind == "SET_MODE":
            self.requested_mode[176] = (before, msg.custom_mode)
        elif kind == "COMMAND_LONG" and msg.command == 21:
            self.requested_mode[21] = (before, AUTO_LAND)
        elif kind == "COMMAND_LONG" and msg.command == 22:
            self.requested_mode[22] = (before, AUTO_TAKEOFF)
        elif kind == "COMMAND_LONG" and msg.command == 400:
            self.requested_arm = msg.param1 == 1

    def close(self) -> None:
        self.tlog.close()
        self.conn.close()


@dataclass
class Px4Run:
    """One PX4 SITL process (``run-px4.sh``); stop it with ``stop``."""

    release: str
    instance: int
    workdir: Path
    env: dict[str, str]
    proc: subprocess.Popen[bytes] | None = None

    def start(self) -> None:
        bundle = SITL / self.release
        args = [str(SITL / "run-px4.sh"), str(bundle), str(self.workdir)]
        extra = [f"{k}={v}" for k, v in self.env.items() if not k.startswith("SEED_")]
        if extra:
            args += ["--", *extra]
        env = {**os.environ, "PX4_INSTANCE": str(self.instance)}
        if "SEED_PARAMS" in self.env:
            env["SEED_PARAMS"] = self.env["SEED_PARAMS"]
        log = (self.workdir.parent / f"{self.workdir.name}.px4.log").open("wb")
        self.proc = subprocess.Popen(
            args, stdout=log, stderr=subprocess.STDOUT, env=env, preexec_fn=_normal_priority
        )

    def stop(self) -> Path:
        """SIGINT (PX4 closes its ULog), wait, and return the ULog."""
        assert self.proc is not None
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        logs = sorted(self.workdir.glob("log/*/*.ulg"))
        if not logs:
            raise RuntimeError(f"PX4 wrote no ULog in {self.workdir}")
        return logs[-1]


def _normal_priority() -> None:
    """PX4 runs at the ordinary priority, whatever the driver's (runs.py raises its own)."""
    os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))


@contextmanager
def px4(release: str, instance: int, workdir: Path, env: dict[str, str]) -> Iterator[Px4Run]:
    run = Px4Run(release, instance, workdir, env)
    run.start()
    try:
        yield run
    finally:
        if run.proc is not None and run.proc.poll() is None:
            run.stop()
