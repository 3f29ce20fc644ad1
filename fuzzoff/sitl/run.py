"""The three ways to put a stream in front of real PX4, each ending in a verdict.

- ``run_scenario``: boot a bundle (or the user's build), fly a scenario program, stop PX4;
- ``replay_on_bundle``: boot a bundle and replay a recording into it;
- ``replay_live``: replay a recording into a PX4 that is already running (``replay --to``).

Every run records both directions as a tlog; a run that started PX4 also keeps its ULog.
The verdict compares what PX4 did with the gate model's prediction for the release
(``fuzzoff.sitl.verdict``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field
from pathlib import Path

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl import airframes, bundle, replay
from fuzzoff.sitl.driver import Driver, Step
from fuzzoff.sitl.link import COMPANION_SYSID, Link, LinkError
from fuzzoff.sitl.recorder import TlogRecorder
from fuzzoff.sitl.scenarios import SCENARIOS
from fuzzoff.sitl.session import Session
from fuzzoff.sitl.trim import trim
from fuzzoff.sitl.verdict import Verdict, compare

TAIL_S = 1.5
"""After the last message, PX4's clock runs COM_OF_LOSS_T plus this before the run ends: a
stream that ends in OFFBOARD is lost only then."""
MANUAL_SETTLE_S = 1.5
"""A joystick this long before the stream: PX4 reports manual control within a second."""
Log = Callable[[str], None]


@dataclass(slots=True)
class Outcome:
    tlog: Path
    release: str
    ulog: Path | None = None
    verdict: Verdict | None = None
    steps: list[Step] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def _release_for_model(build_release: str) -> str:
    return build_release.split("-")[0]


def run_scenario(
    name: str,
    build: bundle.Build,
    instance: int,
    out_dir: Path,
    params: dict[str, float] | None = None,
    env: dict[str, str] | None = None,
    log: Log = print,
    vehicle: str | None = None,
) -> Outcome:
    """Fly scenario ``name`` on its own vehicle, or on ``vehicle`` (``--vehicle``)."""
    scenario = SCENARIOS[name]
    airframe = airframes.airframe_for(vehicle or scenario.vehicle)
    env = airframes.boot_env(build, airframe.vehicle, env)
    params = {**scenario.params_for(build.release), **(params or {})}
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = f"{name}-{build.release}"
    tlog = out_dir / f"{stem}.tlog"
    session = Session(build, instance, env=env, log=log)
    try:
        with session:
            result = session.run(
                name, scenario.program, tlog, manual=scenario.manual, params=params
            )
            session.finish(result)
        outcome = Outcome(tlog, build.release, steps=result.steps)
        if result.error:
            outcome.notes.append(f"the scenario stopped: {result.error}")
        if result.ulog is not None:
            outcome.ulog = trim(result.ulog, out_dir / f"{stem}.ulg")
    finally:
        session.px4.cleanup()
    outcome.verdict = compare(
        tlog,
        _release_for_model(build.release),
        outcome.ulog,
        params,
        COMPANION_SYSID,
        airframe.fuzzoff_vehicle,
    )
    return outcome


def _apply_params(link: Link, params: dict[str, float], log: Log) -> dict[str, float]:
    """PARAM_SET with read-back; the previous values (to restore)."""
    before: dict[str, float] = {}
    for name, value in params.items():
        old = link.get_param(name)
        if old is None:
            raise LinkError(f"PX4 has no parameter {name}")
        before[name] = old[0]
        link.set_param(name, value)
        log(f"parameter {name} = {value:g} on PX4 (read back; was {old[0]:g})")
    return before


def start_joystick(driver: Driver, log: Log) -> None:
    """A MAVLink joystick (MANUAL_CONTROL at 10 Hz) for ``MANUAL_SETTLE_S`` before the stream,
    so that PX4 has manual control when it starts, as a reproducer's setup may say."""
    driver.wait(MANUAL_SETTLE_S)
    if driver.link.view.manual_present:
        log("manual control present (a MAVLink joystick, MANUAL_CONTROL at 10 Hz), as assumed")
    else:
        log(
            "PX4 does not report manual control from the MAVLink joystick (COM_RC_IN_MODE?):"
            " the verdict's model follows PX4's SYS_STATUS"
        )


def _replay_on(
    link: Link,
    plan: replay.Plan,
    speed: float,
    timeout_s: float,
    log: Log,
    manual: bool = False,
) -> None:
    driver = Driver(link, manual=manual)
    if manual:
        start_joystick(driver, log)
    for note in replay.bring_to_start(link, plan):
        log(note)
    sent = replay.send(link, plan, speed, driver.tick)
    log(f"sent {len(sent)} messages over {plan.duration / speed:.2f} s of PX4's clock")
    driver.wait(timeout_s + TAIL_S)


def load_plan(recording: Path) -> replay.Plan:
    plan = replay.plan_from_tlog(recording)
    if plan.damaged_at is not None:
        raise LinkError(
            f"{recording}: damaged or cut short at byte {plan.damaged_at} (a packet pymavlink"
            " cannot read): a replay would not be the recording"
        )
    if not plan.messages:
        raise LinkError(f"{recording}: no message from a companion or ground station to send")
    return plan


def replay_on_bundle(
    recording: Path,
    build: bundle.Build,
    instance: int,
    out_dir: Path,
    params: dict[str, float] | None = None,
    speed: float = 1.0,
    env: dict[str, str] | None = None,
    log: Log = print,
    manual: bool = False,
) -> Outcome:
    """``manual``: send a MAVLink joystick throughout (a reproducer that assumed manual
    control present)."""
    plan = load_plan(recording)
    params = params or {}
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = f"{recording.stem}-on-{build.release}"
    tlog = out_dir / f"{stem}.tlog"
    session = Session(build, instance, env=env, log=log)
    outcome = Outcome(tlog, build.release)
    try:
        with session:
            link = session._link()
            session.starting_state()
            _apply_params(link, params, log)
            recorder = TlogRecorder(tlog, clock=link.clock.now)
            link.recorder = recorder
            try:
                link.request_version()
                timeout = params.get("COM_OF_LOSS_T", 1.0)
                _replay_on(link, plan, speed, timeout, log, manual)
            finally:
                link.recorder = None
                recorder.close()
        logs = session.px4.ulogs()
        if logs:
            outcome.ulog = trim(logs[-1], out_dir / f"{stem}.ulg")
    finally:
        session.px4.cleanup()
    outcome.verdict = compare(
        tlog, _release_for_model(build.release), outcome.ulog, params, COMPANION_SYSID
    )
    return outcome


def replay_live(
    recording: Path,
    target: tuple[int, tuple[object, ...]],
    tlog: Path,
    *,
    release: str | None = None,
    params: dict[str, float] | None = None,
    speed: float = 1.0,
    connect_timeout: float = 10.0,
    ready_timeout: float = 90.0,
    log: Log = print,
    manual: bool = False,
) -> Outcome:
    """Replay into a running PX4 at ``target`` (its listening port); parameters set for the
    replay are put back afterwards. ``manual``: a MAVLink joystick throughout."""
    plan = load_plan(recording)
    params = params or {}
    link = Link(target)
    try:
        try:
            link.connect(connect_timeout)
        except LinkError as exc:
            raise LinkError(
                f"{exc}: is PX4 running? It listens on UDP 14580 (+ instance; 14540 is where it"
                " sends)"
            ) from None
        link.request_version()
        link.wait_for(lambda v: v.release is not None, 2.0)
        release = release or link.view.release
        if release is None:
            raise LinkError("PX4 did not say its release (AUTOPILOT_VERSION): give --px4")
        log(f"PX4 {release} (system {link.view.sysid}) answers; waiting until it is ready to arm")
        link.wait_ready(ready_timeout)
        before = _apply_params(link, params, log)
        recorder = TlogRecorder(tlog, clock=link.clock.now)
        link.recorder = recorder
        try:
            link.request_version()
            _replay_on(link, plan, speed, params.get("COM_OF_LOSS_T", 1.0), log, manual)
        finally:
            link.recorder = None
            recorder.close()
            for name, value in before.items():
                link.set_param(name, value)
    finally:
        link.close()
    outcome = Outcome(tlog, release)
    outcome.verdict = compare(tlog, _release_for_model(release), None, params, COMPANION_SYSID)
    return outcome
