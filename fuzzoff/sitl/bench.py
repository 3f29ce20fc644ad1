"""One PX4 for a whole live campaign: put back to a known state before each stream.

``Bench`` boots a bundle once (``Session``) and, before each stream, brings PX4 to where
every stream starts: landed, disarmed (a plain disarm where PX4 counts the vehicle as landed,
else AUTO_LAND), in Hold, the stream's parameters set and read back (the
others at PX4's own values), and a MAVLink joystick running when the stream assumes manual
control. A vehicle that does not land and disarm in time is disarmed by force
(``MAV_CMD_COMPONENT_ARM_DISARM`` with PX4's 21196); a PX4 that died, stopped answering, or is
not ready to arm again in time is restarted (1.15 then needs 35-42 s).

Each stream gets its own ULog: the logger is switched on just before the stream and off after
it (PX4 closes the file within a second or two), so that the verdict reads only that stream's
commands, modes and loss flag. The stream itself goes out as ``fuzzoff replay --to`` sends it
(``replay.send``: from the client's own system id, addressed to the autopilot, on PX4's clock).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import field
from pathlib import Path

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.mavlink_ids import MAV_CMD_COMPONENT_ARM_DISARM
from fuzzoff.sitl import bundle, replay
from fuzzoff.sitl.driver import NAV_LAND, NAV_LOITER, Driver
from fuzzoff.sitl.link import Link, LinkError
from fuzzoff.sitl.recorder import TlogRecorder
from fuzzoff.sitl.run import MANUAL_SETTLE_S, TAIL_S
from fuzzoff.sitl.session import LOGGER_SETTLE_S, Session, apply_params
from fuzzoff.sitl.trim import trim

LAND_TIMEOUT_S = 45.0
"""AUTO_LAND from the height a stream reaches in a few seconds (at most ~20 m) and the
auto-disarm after touchdown."""
FORCE_DISARM = 21196.0
"""``param2`` of MAV_CMD_COMPONENT_ARM_DISARM that makes PX4 disarm in the air too."""
READY_AGAIN_S = 20.0
"""How long PX4 may take to pass its pre-arm checks again after a stream before it is
restarted instead."""
MANUAL_CHANGE_S = 3.0
"""PX4 reports a joystick found or lost within a second (COM_RC_LOSS_T 0.5 s, SYS_STATUS)."""
LOGGER_OPEN_S = 3.0
LOGGER_CLOSE_S = 8.0
"""PX4 writes out its buffer after ``logger off``: a second or two on an idle machine."""
STATUS_WAIT_S = 2.5
"""PX4 sends HEARTBEAT and SYS_STATUS about once a second."""
SILENT_S = 3.0
"""No HEARTBEAT from PX4 for this long: it is restarted."""
Log = Callable[[str], None]


def _wait_ready(link: Link, driver: Driver) -> str | None:
    """Wait up to ``READY_AGAIN_S`` for PX4's pre-arm bit (SYS_STATUS); None once it is set,
    else PX4's newest message, which says why not."""
    deadline = time.monotonic() + READY_AGAIN_S
    while not link.view.prearm_ok:
        if time.monotonic() > deadline:
            return link.view.statustexts[-1][1] if link.view.statustexts else "nothing"
        driver.wait(0.1)
    return None


class NeedsRestart(LinkError):
    """PX4 cannot be brought back to the starting state: restart it (the message says why)."""


@dataclass(slots=True)
class LiveRun:
    """One stream sent to PX4: the exchange and what was sent when."""

    tlog: Path
    ulog: Path | None
    meant: list[float]
    """Each message's time from the first, as the stream meant it."""
    sent: list[float]
    """The PX4 time each one went out, as the tlog records it."""
    params: dict[str, float]
    manual: bool | None
    """PX4's own verdict on manual control when the stream started (SYS_STATUS)."""
    recording_from: float
    """PX4's time when the tlog started: PX4 logs the newest sample of each topic when its
    logger starts, so its ULog shows the reset's last command from before (left out)."""
    notes: list[str] = field(default_factory=list)


class Bench:
    def __init__(
        self,
        build: bundle.Build,
        instance: int,
        log: Log = print,
        env: dict[str, str] | None = None,
        lands: bool = True,
        fixes: dict[str, float] | None = None,
    ) -> None:
        self.build = build
        self.lands = lands
        self.fixes = dict(fixes or {})
        """Set at each boot and kept (``airframes.Airframe.fixes``): what makes SIH fly the
        airframe as PX4 means it."""
        """AUTO_LAND brings it down (a multicopter, a VTOL); else (an airplane, which lands
        only on a mission's runway) a vehicle PX4 will not disarm plainly is disarmed by force."""
        self.instance = instance
        self.env = dict(env or {})
        """``PX4_*`` variables for each boot (``PX4_SIM_MODEL``: the airframe)."""
        self.log = log
        self.session: Session | None = None
        self.boots: list[float] = []
        """Seconds from start to ready, per boot."""
        self.defaults: dict[str, float] = {}
        """PX4's own value of every parameter a stream set (read before the first set)."""
        self.current: dict[str, float] = {}
        self.manual = False
        """The joystick is running (between streams too, so that PX4 keeps manual control
        while it lands)."""

    # -- PX4's life

    def start(self) -> None:
        started = time.monotonic()
        session = Session(self.build, self.instance, env=self.env, log=self.log)
        try:
            session.connect()
            if session.link is not None and self.fixes:
                apply_params(session.link, self.fixes)
            session.px4.command("logger", "off")
            self._wait_closed(session)
        except BaseException:
            session.close()
            session.px4.cleanup()
            raise
        self.session = session
        self.boots.append(time.monotonic() - started)
        self.current = {}
        self.manual = False

    def close(self) -> None:
        if self.session is not None:
            self.session.close()
            self.session.px4.cleanup()
            self.session = None

    def restart(self, why: str) -> None:
        self.log(f"restarting PX4 {self.build.release}: {why}")
        self.close()
        self.start()

    @property
    def restarts(self) -> int:
        return max(0, len(self.boots) - 1)

    def _link(self) -> Link:
        if self.session is None or self.session.link is None:
            raise NeedsRestart("not connected")
        return self.session.link

    def _driver(self) -> Driver:
        return Driver(self._link(), manual=self.manual)

    # -- the starting state

    def prepare(self, params: dict[str, float], manual: bool) -> list[str]:
        """Landed, disarmed, in Hold, ``params`` set (the rest at PX4's values), the joystick
        as ``manual`` says; restart PX4 where that cannot be done. What was done, for the
        record."""
        notes: list[str] = []
        for attempt in range(2):
            try:
                self._alive()
                self._land_and_hold(notes)
                self._params(params, notes)
                self._joystick(manual, notes)
                return notes
            except (NeedsRestart, LinkError) as exc:
                if attempt:
                    raise LinkError(f"PX4 cannot be brought to the starting state: {exc}") from None
                self.restart(str(exc))
                notes.append(f"PX4 restarted: {exc}")
        return notes

    def _alive(self) -> None:
        if self.session is None:
            raise NeedsRestart("not started")
        if not self.session.px4.alive():
            raise NeedsRestart(f"PX4 exited ({self.session.px4.console_tail(2)})")
        if time.monotonic() - self._link().view.heartbeat_host > SILENT_S:
            raise NeedsRestart(f"no HEARTBEAT for {SILENT_S:g} s")

    def _land_and_hold(self, notes: list[str]) -> None:
        link = self._link()
        driver = self._driver()
        if link.view.armed:
            # PX4 takes a plain disarm only when it counts the vehicle as landed: an airplane or
            # a rover rolling on the ground, a multicopter that never lifted off
            ack = link.arm(False)
            if ack is not None and ack.result == 0:
                link.wait_for(lambda v: v.armed is False, 3.0)
        if link.view.armed and self.lands:
            ack = link.set_mode(NAV_LAND)
            if ack is not None and ack.result == 0:
                deadline = time.monotonic() + LAND_TIMEOUT_S
                while link.view.armed and time.monotonic() < deadline:
                    driver.wait(0.5)
        if link.view.armed:
            link.command(MAV_CMD_COMPONENT_ARM_DISARM, 0.0, FORCE_DISARM)
            link.wait_for(lambda v: v.armed is False, 3.0)
            why = "it did not land in time" if self.lands else "PX4 did not count it as landed"
            notes.append(f"disarmed by force ({why})")
        if link.view.armed:
            raise NeedsRestart("still armed after landing and a forced disarm")
        if link.view.nav_state != NAV_LOITER:
            ack = link.set_mode(NAV_LOITER)
            if (
                ack is None
                or ack.result != 0
                or not link.wait_for(lambda v: v.nav_state == NAV_LOITER, 3.0)
            ):
                raise NeedsRestart("PX4 does not go to Hold (AUTO_LOITER)")
        said = _wait_ready(link, driver)
        if said is not None:
            raise NeedsRestart(
                f"not ready to arm again within {READY_AGAIN_S:g} s (PX4 said: {said})"
            )

    def _params(self, params: dict[str, float], notes: list[str]) -> None:
        link = self._link()
        for name in params:
            if name not in self.defaults:
                got = link.get_param(name)
                if got is None:
                    raise LinkError(f"PX4 has no parameter {name}")
                self.defaults[name] = got[0]
        want = {**self.defaults, **params}
        for name, value in want.items():
            old = self.current.get(name, self.defaults[name])
            if abs(old - value) > 1e-4 * max(1.0, abs(value)):
                self.current[name] = link.set_param(name, value)
                notes.append(f"{name} = {value:g} (read back)")

    def _joystick(self, manual: bool, notes: list[str]) -> None:
        link = self._link()
        if manual == self.manual and (link.view.manual_present or False) == manual:
            return
        self.manual = manual
        driver = self._driver()
        deadline = time.monotonic() + MANUAL_CHANGE_S
        driver.wait(MANUAL_SETTLE_S if manual else 0.6)
        while (link.view.manual_present or False) != manual and time.monotonic() < deadline:
            driver.wait(0.2)
        if (link.view.manual_present or False) != manual:
            notes.append(
                f"PX4 does not report manual control {'present' if manual else 'lost'}"
                f" {MANUAL_CHANGE_S:g} s after the joystick {'started' if manual else 'stopped'}"
            )

    # -- one stream

    def send(self, plan: replay.Plan, params: dict[str, float], tlog: Path, ulog: Path) -> LiveRun:
        """Send ``plan`` (PX4 already prepared), recording both directions in ``tlog`` and
        PX4's own log of it in ``ulog`` (cut to the topics fuzzoff reads)."""
        session = self.session
        if session is None:
            raise LinkError("PX4 is not running")
        link = self._link()
        driver = self._driver()
        before = set(session.px4.ulogs())
        session.px4.command("logger", "on")
        deadline = time.monotonic() + LOGGER_OPEN_S
        while not set(session.px4.ulogs()) - before and time.monotonic() < deadline:
            driver.wait(0.1)
        notes = list(replay.bring_to_start(link, plan))
        manual = link.view.manual_present
        recorder = TlogRecorder(tlog, clock=link.clock.now)
        link.recorder = recorder
        recording_from = link.clock.now()
        try:
            link.request_version()
            driver.wait(LOGGER_SETTLE_S)
            # The model reads the starting mode and manual control from the tlog: one
            # HEARTBEAT and one SYS_STATUS (about 1 Hz) before the stream, or it takes its
            # first HEARTBEAT in OFFBOARD for a recording that starts there.
            since = time.monotonic()
            deadline = since + STATUS_WAIT_S
            while time.monotonic() < deadline and (
                link.view.heartbeat_host < since or link.view.sys_status_host < since
            ):
                driver.wait(0.05)
            # Ready to arm in that SYS_STATUS too: a health failure can come after the
            # reset found PX4 ready ("Preflight Fail: horizontal velocity unstable" 0.5 s
            # after a landing refused the stream's arm in a live 1.15 campaign).
            said = _wait_ready(link, driver)
            if said is not None:
                notes.append(f"PX4 was not ready to arm when the stream began (it said: {said})")
            sent = replay.send(link, plan, 1.0, driver.tick)
            driver.wait(params.get("COM_OF_LOSS_T", 1.0) + TAIL_S)
        finally:
            link.recorder = None
            recorder.close()
            session.px4.command("logger", "off")
            self._wait_closed(session)
        fresh = sorted(set(session.px4.ulogs()) - before, key=lambda p: p.stat().st_mtime)
        kept = None
        if fresh:
            try:
                kept = trim(fresh[-1], ulog)
            except Exception as exc:  # pyulog raises bare exceptions on a damaged log
                notes.append(f"PX4's ULog of this stream cannot be read ({exc}): the tlog")
            for path in fresh:
                path.unlink(missing_ok=True)  # several MB each: keep only the cut copy
        else:
            notes.append("PX4 wrote no ULog for this stream: its side is read from the tlog")
        meant = [t for t, _ in plan.messages]
        return LiveRun(tlog, kept, meant, sent, dict(params), manual, recording_from, notes)

    def _wait_closed(self, session: Session) -> None:
        """Until PX4's newest log stops growing (it closes it after ``logger off``)."""
        deadline = time.monotonic() + LOGGER_CLOSE_S
        last = -1
        while time.monotonic() < deadline:
            logs = session.px4.ulogs()
            size = logs[-1].stat().st_size if logs else 0
            if size == last:
                return
            last = size
            time.sleep(0.6)
