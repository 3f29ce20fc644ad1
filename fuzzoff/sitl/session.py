"""One PX4 boot for one run: a fresh PX4, so that nothing carries over between runs.

``Session`` starts a build (``bundle.start``), connects a ``Link`` on the instance's onboard
port, keeps PX4's logger on from boot to exit (``logger on``: the default log closes at disarm
and 1.14/1.15 ignore ``PX4_PARAM_SDLOG_MODE``), waits until PX4 is ready to arm, and quiets the
busy telemetry. ``run`` brings the vehicle to the starting state (landed, disarmed, in Hold),
applies the run's parameters with read-back, records the exchange and runs the program;
``close`` stops PX4 with SIGINT, which closes the ULog.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import field
from pathlib import Path

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl import bundle
from fuzzoff.sitl.driver import NAV_LOITER, Driver, Step
from fuzzoff.sitl.link import Link, LinkError
from fuzzoff.sitl.recorder import TlogRecorder

BOOT_TIMEOUT_S = 30.0
READY_TIMEOUT_S = 90.0
"""PX4 1.15 passes its arming checks 35-42 s after boot on an idle machine; slack for a busy one."""
LOGGER_SETTLE_S = 0.5
RENAMED: dict[str, tuple[str, Callable[[float], float]]] = {
    "FW_USE_AIRSPD": ("FW_ARSP_MODE", lambda use: 0.0 if use else 1.0),
    "SIH_F_T_MAX": ("SIH_T_MAX", lambda newtons: newtons),
}
"""A parameter a run sets -> its name and value on a PX4 that predates the name: 1.15 renamed
``FW_ARSP_MODE`` (1: do not use the airspeed) to ``FW_USE_AIRSPD`` and inverted it (PX4's
``param_translation.cpp``, 2023-12-06); 1.18's SIH takes a fixed wing's propeller thrust from
``SIH_F_T_MAX``, where earlier SIH took it from ``SIH_T_MAX`` (``airframes.AIRPLANE_THRUST``)."""


@dataclass(slots=True)
class RunResult:
    name: str
    tlog: Path
    ulog: Path | None
    steps: list[Step]
    error: str | None = None
    params: dict[str, float] = field(default_factory=dict)


def apply_params(link: Link, params: dict[str, float]) -> dict[str, float]:
    """Set ``params`` with read-back (under its older name where PX4 predates one, ``RENAMED``):
    the names and values PX4 holds now."""
    applied: dict[str, float] = {}
    for name, value in params.items():
        if name in RENAMED:
            try:
                applied[name] = link.set_param(name, value)
                continue
            except LinkError as exc:
                if "has no parameter" not in str(exc):
                    raise
            old, convert = RENAMED[name]
            name, value = old, convert(value)
        applied[name] = link.set_param(name, value)
    return applied


class Session:
    def __init__(
        self,
        build: bundle.Build,
        instance: int,
        *,
        env: dict[str, str] | None = None,
        log: Callable[[str], None] = print,
    ) -> None:
        self.build = build
        self.log = log
        self.px4 = bundle.start(build, instance, env)
        self.link: Link | None = None
        self.ready_s = 0.0

    def __enter__(self) -> Session:
        try:
            self.connect()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def connect(self) -> None:
        started = time.monotonic()
        self.link = Link(f"udpin:127.0.0.1:{self.px4.send_port}")
        try:
            self.link.connect(BOOT_TIMEOUT_S)
        except LinkError as exc:
            tail = self.px4.console_tail()
            raise LinkError(f"PX4 {self.build.release}: {exc}; its console: {tail}") from None
        self.px4.command("logger", "on")
        self.link.quiet_telemetry()
        self.ready_s = time.monotonic() - started + self.link.wait_ready(READY_TIMEOUT_S)
        self.log(f"PX4 {self.build.release} ready to arm {self.ready_s:.1f} s after start")

    def close(self) -> None:
        if self.link is not None:
            self.link.close()
            self.link = None
        self.px4.stop()

    def starting_state(self) -> None:
        """Landed, disarmed, in Hold: where every scenario starts."""
        link = self._link()
        if link.view.armed:
            Driver(link).land_and_wait()
        if link.view.nav_state != NAV_LOITER:
            ack = link.set_mode(NAV_LOITER)
            if ack is None or ack.result != 0:
                raise LinkError("cannot bring the vehicle to Hold (AUTO_LOITER) before the run")
        link.wait_for(lambda v: v.nav_state == NAV_LOITER, 3.0)
        if not link.wait_for(lambda v: v.prearm_ok, READY_TIMEOUT_S):
            raise LinkError("PX4 is not ready to arm again after the previous run")

    def run(
        self,
        name: str,
        program: Callable[[Driver], None],
        tlog: Path,
        *,
        manual: bool = False,
        params: dict[str, float] | None = None,
    ) -> RunResult:
        link = self._link()
        self.starting_state()
        applied = apply_params(link, params or {})
        recorder = TlogRecorder(tlog, clock=link.clock.now)
        driver = Driver(link, manual=manual)
        error = None
        try:
            link.recorder = recorder
            link.request_version()
            driver.wait(LOGGER_SETTLE_S)
            program(driver)
            driver.wait(LOGGER_SETTLE_S)
        except LinkError as exc:
            error = str(exc)
        finally:
            link.recorder = None
            recorder.close()
        return RunResult(name, tlog, None, driver.steps, error, applied)

    def finish(self, result: RunResult) -> RunResult:
        """Stop PX4 and give the run its ULog (still in PX4's working folder)."""
        self.close()
        logs = self.px4.ulogs()
        result.ulog = logs[-1] if logs else None
        return result

    def _link(self) -> Link:
        if self.link is None:
            raise LinkError("not connected")
        return self.link
