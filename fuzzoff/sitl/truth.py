"""What PX4 did, read from its own ULog: commands and acks, mode history, the loss flag.

Times are PX4's boot time in seconds (the ULog's timestamps), the clock the model's prediction
is shifted onto (``fuzzoff.sitl.verdict``). Read with pyulog, only the topics needed.
"""

from __future__ import annotations

from dataclasses import field
from pathlib import Path
from struct import error as struct_error

from pyulog import ULog

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.recording import SourceError

TOPICS = [
    "vehicle_command",
    "vehicle_command_ack",
    "vehicle_status",
    "failsafe_flags",
    "offboard_control_mode",
    "vehicle_land_detected",
]
ARMED = 2
ACK_WINDOW_S = 0.1
"""PX4 1.16/1.17 ack a mode switch twice within 4-12 ms: the last ack in this window counts."""
ACK_MAX_DELAY_S = 1.0


@dataclass(frozen=True, slots=True)
class Request:
    t: float
    command: int
    param1: float
    param2: float
    param3: float
    result: int | None
    """The last ack's result, None when PX4 logged no ack."""


@dataclass(frozen=True, slots=True)
class Mode:
    t: float
    nav_state: int
    armed: bool
    intention: int | None


@dataclass(slots=True)
class Truth:
    requests: list[Request] = field(default_factory=list)
    modes: list[Mode] = field(default_factory=list)
    loss_flag: list[tuple[float, bool]] = field(default_factory=list)
    """(time, lost) at every change of ``failsafe_flags.offboard_control_signal_lost``."""
    keepalives: list[float] = field(default_factory=list)
    texts: list[tuple[float, str]] = field(default_factory=list)
    landed: list[tuple[float, bool]] = field(default_factory=list)
    """(time, landed or maybe_landed) at every change of PX4's land detector (ULog only)."""
    span: tuple[float, float] | None = None
    """The first and the last timestamp of the ULog (PX4's clock), None from a tlog."""

    def landed_since(self, t: float) -> tuple[bool, float] | None:
        """PX4's land verdict at ``t`` and when it last changed (None: not recorded)."""
        found = None
        for change in self.landed:
            if change[0] > t:
                break
            found = change
        return None if found is None else (found[1], found[0])

    def mode_at(self, t: float) -> Mode | None:
        found = None
        for mode in self.modes:
            if mode.t > t:
                break
            found = mode
        return found

    def last_keepalive_before(self, t: float) -> float | None:
        found = None
        for k in self.keepalives:
            if k > t:
                break
            found = k
        return found


def read_truth(path: Path, client_sysid: int | None = None) -> Truth:
    """PX4's record of a run; ``client_sysid`` keeps only that client's commands."""
    try:
        log = ULog(str(path), message_name_filter_list=TOPICS)
    except Exception as exc:  # pyulog raises bare exceptions on damage
        raise SourceError(str(path), f"not a readable ULog: {exc}") from None
    data = {d.name: d.data for d in log.data_list if d.multi_id == 0}
    truth = Truth()
    acks: list[tuple[float, int, int]] = []
    ack = data.get("vehicle_command_ack")
    if ack is not None:
        acks = [
            (int(t) / 1e6, int(c), int(r))
            for t, c, r in zip(ack["timestamp"], ack["command"], ack["result"], strict=True)
        ]
    cmd = data.get("vehicle_command")
    if cmd is not None:
        for i, t in enumerate(cmd["timestamp"]):
            external = bool(cmd["from_external"][i]) if "from_external" in cmd else True
            sysid = int(cmd["source_system"][i])
            if not external or (client_sysid is not None and sysid != client_sysid):
                continue
            ts, command = int(t) / 1e6, int(cmd["command"][i])
            truth.requests.append(
                Request(
                    ts,
                    command,
                    float(cmd["param1"][i]),
                    float(cmd["param2"][i]),
                    float(cmd["param3"][i]),
                    _result(acks, ts, command),
                )
            )
    status = data.get("vehicle_status")
    if status is not None:
        intention = status.get("nav_state_user_intention")
        last: tuple[int, bool] | None = None
        for i, t in enumerate(status["timestamp"]):
            key = (int(status["nav_state"][i]), int(status["arming_state"][i]) == ARMED)
            if key != last:
                truth.modes.append(
                    Mode(int(t) / 1e6, *key, None if intention is None else int(intention[i]))
                )
                last = key
    flags = data.get("failsafe_flags")
    if flags is not None and "offboard_control_signal_lost" in flags:
        prev: bool | None = None
        for t, lost in zip(flags["timestamp"], flags["offboard_control_signal_lost"], strict=True):
            if bool(lost) != prev:
                truth.loss_flag.append((int(t) / 1e6, bool(lost)))
                prev = bool(lost)
    ocm = data.get("offboard_control_mode")
    if ocm is not None:
        truth.keepalives = sorted({int(t) / 1e6 for t in ocm["timestamp"]})
    land = data.get("vehicle_land_detected")
    if land is not None and "landed" in land:
        maybe = land.get("maybe_landed", land["landed"])
        was: bool | None = None
        for t, landed, maybe_landed in zip(land["timestamp"], land["landed"], maybe, strict=True):
            now = bool(landed) or bool(maybe_landed)
            if now != was:
                truth.landed.append((int(t) / 1e6, now))
                was = now
    truth.texts = [(m.timestamp / 1e6, m.message) for m in log.logged_messages]
    truth.span = (log.start_timestamp / 1e6, log.last_timestamp / 1e6)
    return truth


SIM_STALL_TEXT = "SIH lockstep: timed out"
"""What main-2026-08-13's SIH logs while its clock waits for actuator outputs that do not come
(OFFBOARD disarmed without a setpoint PX4 takes, the Ackermann rover armed; docs/sitl.md)."""
STALLED_SHARE = 0.5


def sim_stalled(truth: Truth, sent_s: float) -> str | None:
    """Why PX4's record of a stream of ``sent_s`` seconds cannot be judged, when SIH stopped
    PX4's clock in it: the lockstep timeout logged and the ULog spanning less than half the
    stream on PX4's clock (a lone timeout on a loaded host delays the clock without stopping
    it). None when it ran."""
    if truth.span is None or sent_s <= 0:
        return None
    first, last = truth.span
    said = next((t for t, text in truth.texts if SIM_STALL_TEXT in text), None)
    if said is None or last - first >= STALLED_SHARE * sent_s:
        return None
    return (
        f"PX4's simulated clock stopped {said - first:.1f} s into its log of the stream (SIH:"
        f" '{SIM_STALL_TEXT} waiting for actuator_outputs_sim'; its log spans {last - first:.1f}"
        f" s of the {sent_s:.1f} s sent): PX4 ran nothing after it"
    )


def _result(acks: list[tuple[float, int, int]], t: float, command: int) -> int | None:
    mine = [a for a in acks if a[1] == command and t - 0.002 <= a[0] <= t + ACK_MAX_DELAY_S]
    if not mine:
        return None
    first = mine[0][0]
    return [a for a in mine if a[0] <= first + ACK_WINDOW_S][-1][2]


@dataclass(slots=True)
class TlogView:
    """What the client's tlog shows of PX4: the same record as a ``Truth`` (HEARTBEAT modes,
    COMMAND_ACKs; no loss flag), and ``offset``: PX4's boot time minus the tlog's time from its
    first record, from PX4's stamped TIMESYNC and SYSTEM_TIME messages."""

    truth: Truth
    offset: float | None


def read_tlog(path: Path) -> TlogView:
    """PX4's side of a client's tlog (raises ``SourceError`` for a file that is no tlog)."""
    from statistics import median

    from fuzzoff.modes import custom_mode_to_nav_state
    from fuzzoff.sitl.link import open_tlog

    truth = Truth()
    stamped: list[tuple[float, int, float]] = []
    commands: list[tuple[float, int, int, float, float, float]] = []
    acks: list[tuple[float, int, int, int]] = []
    heartbeats: list[tuple[float, int, int, bool]] = []
    setpoints: list[tuple[float, int]] = []
    first: float | None = None
    autopilot: int | None = None
    log = open_tlog(path)
    try:
        while True:
            msg = log.recv_msg()
            if msg is None:
                break
            kind = msg.get_type()
            if kind == "BAD_DATA":
                continue
            stamp = float(msg._timestamp)
            first = stamp if first is None else first
            t = stamp - first
            src = msg.get_srcSystem()
            if kind == "HEARTBEAT" and msg.autopilot == 12 and msg.get_srcComponent() == 1:
                autopilot = src if autopilot is None else autopilot
                nav = custom_mode_to_nav_state(msg.custom_mode)
                heartbeats.append(
                    (t, src, nav if nav is not None else -1, bool(msg.base_mode & 128))
                )
            elif kind == "TIMESYNC" and msg.tc1 == 0 and msg.ts1 > 0:
                stamped.append((t, src, msg.ts1 / 1e9))
            elif kind == "SYSTEM_TIME" and msg.time_boot_ms > 0:
                stamped.append((t, src, msg.time_boot_ms / 1e3))
            elif kind == "COMMAND_LONG":
                commands.append(
                    (
                        t,
                        src,
                        int(msg.command),
                        float(msg.param1),
                        float(msg.param2),
                        float(msg.param3),
                    )
                )
            elif kind == "COMMAND_ACK":
                acks.append((t, src, int(msg.command), int(msg.result)))
            elif kind in ("SET_POSITION_TARGET_LOCAL_NED", "SET_ATTITUDE_TARGET"):
                setpoints.append((t, src))
    except (OSError, ValueError, struct_error) as exc:
        raise SourceError(str(path), f"not a readable tlog: {exc}") from None
    finally:
        log.close()
    # The autopilot is known from its first HEARTBEAT, which may come after its first answers.
    last_mode: tuple[int, bool] | None = None
    for t, src, nav, armed in heartbeats:
        if src == autopilot and (nav, armed) != last_mode:
            truth.modes.append(Mode(t, nav, armed, None))
            last_mode = (nav, armed)
    offsets = [px4 - t for t, src, px4 in stamped if src == autopilot]
    truth.keepalives = [t for t, src in setpoints if src != autopilot]
    own_acks = [(t, c, r) for t, src, c, r in acks if src == autopilot]
    commands_sent = [(t, c, p1, p2, p3) for t, src, c, p1, p2, p3 in commands if src != autopilot]
    for t, command, p1, p2, p3 in commands_sent:
        # a retry of the same command (no ack in between) is the same request
        if (
            truth.requests
            and truth.requests[-1].command == command
            and (truth.requests[-1].result is None)
        ):
            truth.requests.pop()
        truth.requests.append(Request(t, command, p1, p2, p3, _result(own_acks, t, command)))
    offset = median(offsets) if offsets else None
    return TlogView(truth, offset)
