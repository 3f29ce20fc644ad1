"""A MAVLink client for a live PX4: an onboard controller with its own system id.

pymavlink with the ``development`` dialect (what PX4 speaks: CURRENT_MODE 436 and the other
ids ``common`` lacks decode, and the rest still reach the recording as their bytes). The client
heartbeats once a second as ``MAV_TYPE_ONBOARD_CONTROLLER`` from ``sysid`` (never 1, the
autopilot's own id), addresses its commands and setpoints to the autopilot it hears, and writes
both directions to a ``TlogRecorder``. A thread reads everything PX4 sends, keeps the newest
state (mode, arming, pre-arm health, acks, parameters) and feeds PX4's clock (``PX4Clock``).
"""

from __future__ import annotations

import os
import socket
import struct
import threading
import time
from collections.abc import Callable
from dataclasses import field
from typing import Any

from fuzzoff.lean_dataclass import dataclass

os.environ.setdefault("MAVLINK20", "1")  # formats.md 7.2: before any pymavlink import

from pymavlink import mavutil
from pymavlink.dialects.v20 import development as mavlink

from fuzzoff.mavlink_ids import (
    MAV_AUTOPILOT_PX4,
    MAV_CMD_COMPONENT_ARM_DISARM,
    MAV_CMD_DO_SET_MODE,
    MAV_CMD_REQUEST_MESSAGE,
    MAV_CMD_SET_MESSAGE_INTERVAL,
    MAV_COMP_ID_ONBOARD_COMPUTER,
    MAV_MODE_FLAG_SAFETY_ARMED,
)
from fuzzoff.modes import custom_mode_to_nav_state, nav_state_to_custom_mode
from fuzzoff.sitl.clock import PX4Clock
from fuzzoff.sitl.recorder import TlogRecorder

DIALECT = "development"
COMPANION_SYSID = 245
"""The client's default system id: not 1 (PX4's), nor 255 (a ground station's usual one)."""
PREARM_BIT = mavlink.MAV_SYS_STATUS_PREARM_CHECK
RC_RECEIVER_BIT = mavlink.MAV_SYS_STATUS_SENSOR_RC_RECEIVER
"""Present and healthy in SYS_STATUS while PX4 has manual control (an RC or a MAVLink joystick)."""
AUTOPILOT_VERSION_ID = 148
BUSY_TELEMETRY = {
    "ATTITUDE": 30,
    "HIGHRES_IMU": 105,
    "GLOBAL_POSITION_INT": 33,
    "ATTITUDE_QUATERNION": 31,
    "LOCAL_POSITION_NED": 32,
    "ODOMETRY": 331,
    "ALTITUDE": 141,
    "DISTANCE_SENSOR": 132,
    "ATTITUDE_TARGET": 83,
    "POSITION_TARGET_LOCAL_NED": 85,
    "SERVO_OUTPUT_RAW": 36,
    "VFR_HUD": 74,
    "GPS_RAW_INT": 24,
}
"""What PX4's onboard link streams at 10-100 Hz (about 24 kB/s in all): ``quiet_telemetry``
asks for them once a second, so that a minute of exchange is a recording under 1 MB."""
ACK_SETTLE_S = 0.15
"""After the first COMMAND_ACK, wait this long for a second one: PX4 1.16 and 1.17 ack a mode
switch twice, the receiver's ACCEPTED first and Commander's result 4-9 ms later (gate 4.3)."""
FLOAT_PARAMS = frozenset({"COM_OF_LOSS_T", "COM_OBC_LOSS_T", "COM_RC_LOSS_T", "COM_DL_LOSS_T"})


class UdpClient(mavutil.mavudp):  # type: ignore[misc]
    """pymavlink's UDP link sending to one resolved address of either family (mavudp itself
    is IPv4 only), with send errors raised instead of dropped."""

    def __init__(self, family: int, address: tuple[Any, ...], sysid: int, compid: int) -> None:
        super().__init__("127.0.0.1:0", input=False, source_system=sysid, source_component=compid)
        old: socket.socket = getattr(self, "port")  # noqa: B009 (mavudp's own socket)
        old.close()
        self.port: socket.socket = socket.socket(family, socket.SOCK_DGRAM)
        self.port.setblocking(False)
        self.fd = self.port.fileno()
        self.destination_addr = address

    def write(self, buf: bytes) -> None:
        self.port.sendto(buf, self.destination_addr)


def open_tlog(path: Any) -> Any:
    """pymavlink's reader of a .tlog, decoding with the ``development`` dialect."""
    log = mavutil.mavlink_connection(str(path), notimestamps=False, robust_parsing=True)
    log.mav = mavlink.MAVLink(log, srcSystem=255, srcComponent=0)
    log.mav.robust_parsing = True
    return log


class LinkError(RuntimeError):
    """PX4 could not be reached or did not answer: one line for the user."""


@dataclass(frozen=True, slots=True)
class Ack:
    command: int
    result: int
    host: float
    px4: float | None


@dataclass(slots=True)
class VehicleView:
    """The newest of what PX4 told the client."""

    sysid: int | None = None
    compid: int = 1
    nav_state: int | None = None
    armed: bool | None = None
    heartbeat_host: float = 0.0
    prearm_known: bool = False
    prearm_ok: bool = False
    manual_present: bool | None = None
    """PX4's own verdict on manual control (SYS_STATUS), None before the first SYS_STATUS."""
    sys_status_host: float = 0.0
    landed_state: int | None = None
    relative_alt_m: float | None = None
    acks: list[Ack] = field(default_factory=list)
    params: dict[str, tuple[float, int]] = field(default_factory=dict)
    statustexts: list[tuple[float, str]] = field(default_factory=list)
    release: str | None = None
    """From AUTOPILOT_VERSION ``flight_sw_version`` (major, minor, patch, type bytes)."""


def param_encode(name: str, value: float, param_type: int | None) -> tuple[float, int]:
    """PX4's bytewise encoding: an INT32 parameter travels as the int's bytes in the float."""
    is_int = (
        param_type in (1, 2, 3, 4, 5, 6)
        if param_type is not None
        else (name not in FLOAT_PARAMS and float(value).is_integer())
    )
    if is_int:
        (as_float,) = struct.unpack("<f", struct.pack("<i", int(value)))
        return as_float, param_type or mavlink.MAV_PARAM_TYPE_INT32
    return float(value), param_type or mavlink.MAV_PARAM_TYPE_REAL32


def param_decode(value: float, param_type: int) -> float:
    if param_type in (1, 2, 3, 4, 5, 6):
        (as_int,) = struct.unpack("<i", struct.pack("<f", value))
        return float(as_int)
    return float(value)


class Link:
    """One MAVLink connection to PX4: ``udpin:HOST:PORT`` (listen where PX4 sends, as in a
    SITL the client starts), or ``(family, address)`` to send to PX4's listening port."""

    def __init__(
        self,
        address: str | tuple[int, tuple[Any, ...]],
        *,
        sysid: int = COMPANION_SYSID,
        compid: int = MAV_COMP_ID_ONBOARD_COMPUTER,
        recorder: TlogRecorder | None = None,
        on_message: Callable[[Any], None] | None = None,
    ) -> None:
        if sysid == 1:
            raise LinkError("system id 1 is the autopilot's own: the client needs another")
        if isinstance(address, str):
            self.conn: Any = mavutil.mavlink_connection(
                address, source_system=sysid, source_component=compid
            )
        else:
            self.conn = UdpClient(address[0], address[1], sysid, compid)
        # The dialect is set on this connection only: mavutil's ``dialect=`` would change the
        # module-wide default that other readers in the process rely on.
        self.mav: Any = mavlink.MAVLink(self.conn, srcSystem=sysid, srcComponent=compid)
        self.mav.robust_parsing = True
        self.conn.mav = self.mav
        self.clock = PX4Clock()
        self.view = VehicleView()
        self.recorder = recorder
        self.on_message = on_message
        self._send_lock = threading.Lock()
        self._cond = threading.Condition()
        self._stop = threading.Event()
        self.mav.set_send_callback(self._sent)
        self._reader = threading.Thread(target=self._read, name="fuzzoff-mavlink", daemon=True)
        self._beat = threading.Thread(target=self._heartbeat, name="fuzzoff-heartbeat", daemon=True)
        self._reader.start()
        self._beat.start()

    # -- plumbing

    def _sent(self, msg: Any) -> None:
        if self.recorder is not None and self.clock.synced:
            self.recorder.write(msg)

    def _read(self) -> None:
        while not self._stop.is_set():
            try:
                msg = self.conn.recv_match(blocking=True, timeout=0.05)
            except (OSError, ValueError):
                if self._stop.is_set():
                    return
                time.sleep(0.01)
                continue
            if msg is None or msg.get_type() == "BAD_DATA":
                continue
            host = time.monotonic()
            self.clock.observe(msg, host)
            if self.recorder is not None and self.clock.synced:
                # after any send under way has recorded its message: pymavlink records a sent
                # message after writing it, and an answer that came in between would otherwise
                # be recorded before its command (seen on a busy host)
                with self._send_lock:
                    self.recorder.write(msg)
            with self._cond:
                self._update(msg, host)
                self._cond.notify_all()
            if self.on_message is not None:
                self.on_message(msg)

    def _update(self, msg: Any, host: float) -> None:
        kind = msg.get_type()
        view = self.view
        src = msg.get_srcSystem()
        if kind == "HEARTBEAT":
            if msg.autopilot != MAV_AUTOPILOT_PX4 or msg.get_srcComponent() != 1:
                return
            if view.sysid is None:
                view.sysid = src
            if src == view.sysid:
                view.nav_state = custom_mode_to_nav_state(msg.custom_mode)
                view.armed = bool(msg.base_mode & MAV_MODE_FLAG_SAFETY_ARMED)
                view.heartbeat_host = host
            return
        if view.sysid is not None and src != view.sysid:
            return
        if kind == "SYS_STATUS":
            # PX4 sets the bit in ``health`` only (not in ``present``) when its checks pass.
            view.prearm_ok = bool(msg.onboard_control_sensors_health & PREARM_BIT)
            view.prearm_known = view.prearm_known or view.prearm_ok
            rc = msg.onboard_control_sensors_present & msg.onboard_control_sensors_health
            view.manual_present = bool(rc & RC_RECEIVER_BIT)
            view.sys_status_host = host
        elif kind == "EXTENDED_SYS_STATE":
            view.landed_state = msg.landed_state
        elif kind == "GLOBAL_POSITION_INT":
            view.relative_alt_m = msg.relative_alt / 1000.0
        elif kind == "COMMAND_ACK":
            px4 = self.clock.now(host) if self.clock.synced else None
            view.acks.append(Ack(msg.command, msg.result, host, px4))
        elif kind == "PARAM_VALUE":
            name = msg.param_id.rstrip("\x00")
            view.params[name] = (param_decode(msg.param_value, msg.param_type), msg.param_type)
        elif kind == "AUTOPILOT_VERSION":
            sw = int(msg.flight_sw_version)
            view.release = f"{(sw >> 24) & 0xFF}.{(sw >> 16) & 0xFF}.{(sw >> 8) & 0xFF}"
        elif kind == "STATUSTEXT":
            view.statustexts.append((host, str(msg.text)))

    def _heartbeat(self) -> None:
        while not self._stop.wait(1.0 if self.view.sysid is not None else 0.2):
            self.heartbeat()

    def heartbeat(self) -> None:
        self.send(
            self.mav.heartbeat_encode(
                mavlink.MAV_TYPE_ONBOARD_CONTROLLER,
                mavlink.MAV_AUTOPILOT_INVALID,
                0,
                0,
                mavlink.MAV_STATE_ACTIVE,
            )
        )

    def send(self, msg: Any) -> None:
        with self._send_lock:
            try:
                self.mav.send(msg)
            except OSError as exc:
                raise LinkError(f"cannot send to PX4: {exc.strerror or exc}") from None

    def send_bytes(self, data: bytes, msg: Any | None = None) -> None:
        """Send a packet as recorded (a replay), recording its parsed form."""
        with self._send_lock:
            self.conn.write(data)
            if msg is not None:
                self._sent(msg)

    def close(self) -> None:
        self._stop.set()
        self._beat.join(2.0)
        self._reader.join(2.0)
        self.conn.close()

    def wait_for(self, condition: Callable[[VehicleView], bool], timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        with self._cond:
            while not condition(self.view):
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._cond.wait(min(left, 0.2))
        return True

    @property
    def target(self) -> tuple[int, int]:
        if self.view.sysid is None:
            raise LinkError("no autopilot heard yet")
        return self.view.sysid, self.view.compid

    # -- waiting for PX4

    def connect(self, timeout: float) -> None:
        """Wait for PX4's HEARTBEAT and its clock (TIMESYNC or SYSTEM_TIME)."""
        if not self.wait_for(lambda v: v.sysid is not None, timeout):
            raise LinkError(f"no PX4 HEARTBEAT within {timeout:.0f} s")
        deadline = time.monotonic() + min(timeout, 5.0)
        while not self.clock.synced:
            if time.monotonic() > deadline:
                raise LinkError("PX4 sends no TIMESYNC or SYSTEM_TIME: its clock is unknown")
            time.sleep(0.05)

    def wait_ready(self, timeout: float) -> float:
        """Wait until PX4 passes its pre-arm checks (SYS_STATUS pre-arm bit); the seconds it
        took. PX4 1.15 needs about 35-42 s after boot, the other releases 5-10 s."""
        start = time.monotonic()
        if not self.wait_for(lambda v: v.prearm_ok, timeout):
            raise LinkError(
                f"PX4 did not pass its pre-arm checks within {timeout:.0f} s (the pre-arm bit of"
                " SYS_STATUS never set): it is not ready to arm"
            )
        return time.monotonic() - start

    # -- commands

    def command(
        self,
        command: int,
        *params: float,
        timeout: float = 1.5,
        retries: int = 2,
        target: tuple[int, int] | None = None,
    ) -> Ack | None:
        """COMMAND_LONG to the autopilot (or to ``target``, system and component); the last of
        its acks (PX4 1.16/1.17 send two for a mode switch), or None when PX4 never acked it."""
        values = [*params, *([0.0] * (7 - len(params)))]
        sysid, compid = self.target if target is None else target
        for attempt in range(retries + 1):
            with self._cond:
                seen = len(self.view.acks)
            self.send(self.mav.command_long_encode(sysid, compid, command, attempt, *values[:7]))

            def acked(v: VehicleView, n: int = seen) -> bool:
                return any(a.command == command for a in v.acks[n:])

            if not self.wait_for(acked, timeout):
                continue
            time.sleep(ACK_SETTLE_S)
            with self._cond:
                acks = [a for a in self.view.acks[seen:] if a.command == command]
            return acks[-1]
        return None

    def set_mode(self, nav_state: int, target: tuple[int, int] | None = None) -> Ack | None:
        custom = nav_state_to_custom_mode(nav_state)
        main, sub = (custom >> 16) & 0xFF, (custom >> 24) & 0xFF
        return self.command(
            MAV_CMD_DO_SET_MODE,
            mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
            main,
            sub,
            target=target,
            retries=0 if target is not None else 2,
            timeout=0.5 if target is not None else 1.5,
        )

    def set_custom_mode(self, main: int, sub: int) -> Ack | None:
        """DO_SET_MODE with a main and sub mode as given (a mode PX4 may not have)."""
        return self.command(
            MAV_CMD_DO_SET_MODE, mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, main, sub, retries=0
        )

    def arm(self, arm: bool = True) -> Ack | None:
        return self.command(MAV_CMD_COMPONENT_ARM_DISARM, 1.0 if arm else 0.0)

    def get_param(self, name: str, timeout: float = 2.0) -> tuple[float, int] | None:
        sysid, compid = self.target
        with self._cond:
            self.view.params.pop(name, None)
        for _ in range(3):
            self.send(self.mav.param_request_read_encode(sysid, compid, name.encode(), -1))
            if self.wait_for(lambda v: name in v.params, timeout / 3):
                return self.view.params[name]
        return None

    def set_param(self, name: str, value: float, timeout: float = 3.0) -> float:
        """PARAM_SET, then the value PX4 reads back; ``LinkError`` when it does not hold."""
        current = self.get_param(name)
        if current is None:
            raise LinkError(f"PX4 has no parameter {name} (no PARAM_VALUE for it)")
        encoded, param_type = param_encode(name, value, current[1])
        sysid, compid = self.target
        with self._cond:
            self.view.params.pop(name, None)
        self.send(self.mav.param_set_encode(sysid, compid, name.encode(), encoded, param_type))
        if not self.wait_for(lambda v: name in v.params, timeout):
            back = self.get_param(name)
        else:
            back = self.view.params[name]
        if back is None or abs(back[0] - value) > 1e-4 * max(1.0, abs(value)):
            got = "nothing" if back is None else f"{back[0]:g}"
            raise LinkError(f"PX4 did not take {name}={value:g} (read back {got})")
        return back[0]

    def quiet_telemetry(self, hz: float = 1.0) -> list[str]:
        """Ask PX4 (MAV_CMD_SET_MESSAGE_INTERVAL) to send ``BUSY_TELEMETRY`` at ``hz``, as a
        companion on a slow link would; the names PX4 refused."""
        refused = []
        for name, msgid in BUSY_TELEMETRY.items():
            ack = self.command(MAV_CMD_SET_MESSAGE_INTERVAL, msgid, 1e6 / hz, timeout=0.5)
            if ack is None or ack.result != 0:
                refused.append(name)
        return refused

    def request_version(self) -> bool:
        """Ask for AUTOPILOT_VERSION (the release, for whoever reads the recording)."""
        ack = self.command(MAV_CMD_REQUEST_MESSAGE, AUTOPILOT_VERSION_ID, timeout=1.0)
        return ack is not None and ack.result == 0

    # -- setpoints

    def position_target(
        self,
        *,
        frame: int = mavlink.MAV_FRAME_LOCAL_NED,
        type_mask: int,
        pos: tuple[float, float, float] = (0.0, 0.0, 0.0),
        vel: tuple[float, float, float] = (0.0, 0.0, 0.0),
        acc: tuple[float, float, float] = (0.0, 0.0, 0.0),
        yaw: float = 0.0,
        yaw_rate: float = 0.0,
    ) -> None:
        sysid, compid = self.target
        boot_ms = int(self.clock.now() * 1000) & 0xFFFFFFFF if self.clock.synced else 0
        self.send(
            self.mav.set_position_target_local_ned_encode(
                boot_ms, sysid, compid, frame, type_mask, *pos, *vel, *acc, yaw, yaw_rate
            )
        )

    def attitude_target(
        self,
        q: tuple[float, float, float, float],
        thrust: float,
        type_mask: int = 0b00000111,
    ) -> None:
        sysid, compid = self.target
        boot_ms = int(self.clock.now() * 1000) & 0xFFFFFFFF if self.clock.synced else 0
        self.send(
            self.mav.set_attitude_target_encode(
                boot_ms, sysid, compid, type_mask, list(q), 0.0, 0.0, 0.0, thrust
            )
        )

    def manual_control(self, x: int = 0, y: int = 0, z: int = 500, r: int = 0) -> None:
        """A MAVLink joystick sample (PX4's COM_RC_IN_MODE 1 takes it as manual control)."""
        sysid, _ = self.target
        self.send(self.mav.manual_control_encode(sysid, x, y, z, r, 0))

    # -- pacing on PX4's clock

    def sleep_until(self, px4_time: float, tick: Callable[[], None] | None = None) -> None:
        """Wait until PX4's clock reads ``px4_time``."""
        while True:
            delay = self.clock.host_delay(px4_time)
            if delay <= 0:
                return
            time.sleep(min(delay, 0.02))
            if tick is not None:
                tick()
