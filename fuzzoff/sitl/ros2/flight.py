"""One flight over PX4's ROS 2 bridge, run inside a private network namespace (``netns``).

PX4 (a bundle with ``uxrce_dds_client``) and the Micro XRCE-DDS Agent start together
(``run-px4.sh`` with ``PX4_AGENT``); a recorder subscribes to the node's inputs to PX4 and to
PX4's outputs as soon as PX4 is on DDS; once PX4 says its pre-flight checks pass, the recording
starts and, ``LEAD_S`` later, the node: a program (``programs.py``, the example's behaviour) or
the replay of a recorded bag's ``/fmu/in`` messages (``replay.py``). When it is done the
recording stops first (as a user stops ``ros2 bag record`` before the node), then PX4, which
closes its ULog. Outputs, in the working folder: ``STEM-mcap/`` and ``STEM-sqlite3/`` (bag
folders), ``STEM.ulg`` (PX4's log cut to the topics fuzzoff reads) and ``STEM.json`` (what
happened, PX4's answers).

Run as ``python -m fuzzoff.sitl.ros2.flight`` by ``netns.run_flight``; needs cyclonedds.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cyclonedds.domain import DomainParticipant

from fuzzoff.formats.rosbag2.writer import Storage
from fuzzoff.profiles import px4_profile_for
from fuzzoff.releases import get as release_record
from fuzzoff.sitl import airframes, bundle
from fuzzoff.sitl.ros2 import agent, external_mode
from fuzzoff.sitl.ros2.bag import Recording, write_bag
from fuzzoff.sitl.ros2.dds import Publisher, idl_type
from fuzzoff.sitl.ros2.example import TICK_S, OffboardControl, now_us
from fuzzoff.sitl.ros2.names import RECEIVED, SENT, BridgeTopic, bridge_topic
from fuzzoff.sitl.ros2.programs import PROGRAMS, Program
from fuzzoff.sitl.ros2.recorder import Recorder
from fuzzoff.sitl.ros2.replay import Plan as ReplayPlan
from fuzzoff.sitl.ros2.replay import load_plan
from fuzzoff.sitl.ros2.rover import ROVER_MESSAGES, RoverNode
from fuzzoff.sitl.ros2.vtol import VtolNode
from fuzzoff.sitl.trim import trim

READY_TIMEOUT_S = 90.0
ARMED = 2
"""VehicleStatus ``arming_state`` ARMING_STATE_ARMED."""
LEAD_S = 0.5
"""The recording starts this long before the node (``ros2 bag record`` started first)."""
REPLAY_TAIL_S = 2.0
"""After a replay's last message: PX4's loss timeout (1 s) and its reaction, recorded."""
Log = Any


class AgentRestart:
    """Stops PX4's agent and starts a new one when the program says (``agent.py``)."""

    def __init__(self, program: Program | None, px4: bundle.Px4Process) -> None:
        self.program = program
        self.px4 = px4
        self.notes: list[tuple[float, str]] = []
        self.stopped_at: float | None = None
        self.new: subprocess.Popen[bytes] | None = None

    def step(self, now: float, armed_at: float | None) -> None:
        stop_after = None if self.program is None else self.program.agent_stop_after_arm_s
        if stop_after is None or armed_at is None or self.new is not None:
            return
        assert self.program is not None
        if self.stopped_at is None and now - armed_at >= stop_after:
            agent.stop(agent.started_pid(self.px4.console))
            self.stopped_at = now
            self.notes.append((now, "the agent is stopped"))
        elif self.stopped_at is not None and now - self.stopped_at >= self.program.agent_down_s:
            folder = bundle.default_root() / "agent"
            self.new = agent.start(folder, self.px4.workdir / "agent-restarted.log")
            self.notes.append((now, "a new agent is started"))

    def close(self) -> None:
        if self.new is not None and self.new.poll() is None:
            self.new.terminate()
            self.new.wait(5.0)


class BridgeFlight:
    """PX4 with its agent, and a recorder on DDS: booted, ready, recorded, stopped."""

    def __init__(
        self,
        release: str,
        program: Program | None,
        log: Log = print,
        vehicle: str | None = None,
        params: dict[str, float] | None = None,
    ) -> None:
        """``vehicle``: the SIH airframe (``airframes``; None: the program's, else the quad);
        ``params``: PX4 parameters set at boot (``PX4_PARAM_<NAME>``)."""
        if "/" in release:  # a build folder (--px4-build)
            self.build = bundle.find_build(None, Path(release))
        else:
            self.build = bundle.find_build(release, None)
        self.log = log
        self.topics_in_only = program is not None and program.topics == "in"
        release_name = self.build.profile_release  # no px4_msgs for it: fails before PX4 starts
        rover = program is not None and program.rover is not None
        moding = program is not None and program.mode is not None
        received = (*RECEIVED, *(external_mode.RECEIVED if moding else ()))
        sent = (
            *SENT,
            *(external_mode.SENT if moding else ()),
            *(ROVER_MESSAGES if rover else ()),
        )
        self.received = [bridge_topic(release_name, m) for m in received]
        self.sent = [bridge_topic(release_name, m) for m in sent]
        env = {"PX4_AGENT": str(bundle.default_root() / "agent"), "PX4_PARAM_SDLOG_MODE": "2"}
        self.vehicle = vehicle or (program.vehicle if program is not None else None)
        fixes = (
            {}
            if self.vehicle is None
            else airframes.fixes_for(airframes.airframe_for(self.vehicle), self.build.release)
        )
        # the airframe's fixes (what makes SIH fly it as PX4 means it), then the caller's
        env |= {f"PX4_PARAM_{k}": f"{v:g}" for k, v in {**fixes, **(params or {})}.items()}
        if self.vehicle is not None:
            env = airframes.boot_env(self.build, self.vehicle, env)
        self.px4 = bundle.start(self.build, 0, env)
        self.restart = AgentRestart(program, self.px4)
        self.participant = DomainParticipant(0)
        recorded = self.sent + ([] if self.topics_in_only else self.received)
        self.recorder = Recorder(self.participant, recorded)
        self.watcher = Recorder(self.participant, self.received) if self.topics_in_only else None
        self.recording = Recording()
        self.ulog: Path | None = None
        self.t0 = 0.0

    @property
    def watch(self) -> Recorder:
        """The recorder that decodes PX4's status and acks."""
        return self.watcher or self.recorder

    def __enter__(self) -> BridgeFlight:
        self.recorder.start()
        if self.watcher is not None:
            self.watcher.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.restart.close()
        self.recorder.close()
        if self.watcher is not None:
            self.watcher.close()
        self.ulog = self.px4.stop()

    def wait_ready(self) -> None:
        started = time.monotonic()
        while not self.watch.watch.status.get("pre_flight_checks_pass"):
            if self.watch.error is not None:
                raise self.watch.error
            if not self.px4.alive() or time.monotonic() - started > READY_TIMEOUT_S:
                raise bundle.BundleError(
                    f"PX4 {self.build.release} not ready on DDS after {READY_TIMEOUT_S:.0f} s: "
                    + self.px4.console_tail()
                )
            time.sleep(0.1)
        took = time.monotonic() - started
        self.log(f"PX4 {self.build.release} on DDS, ready {took:.1f} s after start")

    def record(self) -> None:
        self.recorder.recording = self.recording

    def stop_recording(self) -> None:
        self.recording.stop()
        if self.recorder.error is not None:
            raise self.recorder.error

    def summary(self, name: str, stem: str, notes: list[tuple[float, str]]) -> dict[str, Any]:
        t0 = self.t0
        watch = self.watch.watch
        return {
            "recording": stem,
            "program": name,
            "release": self.build.release,
            "vehicle": self.vehicle or airframes.DEFAULT,
            "notes": [(round(t - t0, 3), n) for t, n in sorted(notes + self.restart.notes)],
            "modes": [(round(t - t0, 3), *rest) for t, *rest in watch.modes],
            "acks": [{**a, "t": round(a["t"] - t0, 3)} for a in watch.acks if a["t"] >= t0],
            "offered": {k: [q._asdict() for q in v] for k, v in self.recorder.offered().items()},
        }

    def write(self, out: Path, stem: str, summary: dict[str, Any]) -> None:
        """After ``__exit__``: the bags, the cut ULog; the summary gets counts and PX4's console."""
        summary["console_tail"] = self.px4.console_tail(3)
        topics = self.sent + self.received
        summary["counts"] = {t.ros_topic: self.recording.count(t.ros_topic) for t in topics}
        storages: tuple[Storage, ...] = ("mcap", "sqlite3")
        for storage in storages:
            target = out / f"{stem}-{storage}"
            write_bag(target, self.recording.records, self.recorder.offered(), storage)
        if self.ulog is not None:
            trim(self.ulog, out / f"{stem}.ulg")
        self.px4.cleanup()


def fly(
    release: str,
    out: Path,
    stem: str,
    program: Program,
    log: Log = print,
    vehicle: str | None = None,
) -> dict[str, Any]:
    """Fly ``program`` on the bundle ``release``; what happened (the run's summary)."""
    if program.mode is not None:
        return fly_mode(release, out, stem, program, log)
    with BridgeFlight(release, program, log, vehicle) as flight:
        flight.wait_ready()
        if program.record_from_s is None:
            flight.record()
            time.sleep(LEAD_S)
        node_participant = DomainParticipant(0)
        by_message = {t.message: t for t in flight.sent}
        node: OffboardControl | RoverNode | VtolNode
        if program.vtol is not None:
            wanted = {"OffboardControlMode", "TrajectorySetpoint", "VehicleCommand"}
            node = VtolNode(
                {m: Publisher(node_participant, by_message[m]) for m in wanted},
                program.vtol,
                armed=lambda: flight.watch.watch.status.get("arming_state") == ARMED,
            )
        elif program.rover is not None:
            wanted = {"OffboardControlMode", "VehicleCommand", *program.rover.messages}
            sinks = {m: Publisher(node_participant, by_message[m]) for m in wanted}
            node = RoverNode(sinks, program.rover)
        else:
            node = OffboardControl(
                {t.message: Publisher(node_participant, t) for t in flight.sent},
                program.plan,
                new_sink=lambda message: Publisher(node_participant, by_message[message]),
            )
        flight.t0 = t0 = time.monotonic()
        tick = t0 + TICK_S
        while True:
            now = time.monotonic()
            flight.restart.step(now, node.armed_at)
            if flight.recorder.recording is None and now - t0 >= (program.record_from_s or 0.0):
                flight.record()
            if node.armed_at is not None and now - node.armed_at >= program.fly_s:
                break
            if now - t0 > program.fly_s + 30:
                break
            if now >= tick:
                node.tick(now)
                tick += TICK_S
            time.sleep(min(0.01, max(0.0, tick - time.monotonic())))
        if program.tail_s > 0:
            time.sleep(program.tail_s)
        flight.stop_recording()
        summary = flight.summary(program.name, stem, node.notes)
    flight.write(out, stem, summary)
    return summary


def fly_mode(
    release: str, out: Path, stem: str, program: Program, log: Log = print
) -> dict[str, Any]:
    """Run an external mode's node (``external_mode.py``) for ``program.fly_s``: PX4 stays
    disarmed; the recording holds the registration and the arming-check exchange."""
    assert program.mode is not None
    with BridgeFlight(release, program, log) as flight:
        api = release_record(px4_profile_for(flight.build.profile_release)).external_mode_api
        if api is None:
            raise bundle.BundleError(f"PX4 {flight.build.release} has no external modes")
        flight.wait_ready()
        flight.record()
        time.sleep(LEAD_S)
        node_participant = DomainParticipant(0)
        node = external_mode.ExternalMode(
            {t.message: Publisher(node_participant, t) for t in flight.sent},
            program.mode,
            api,
        )
        flight.recorder.on_message.update(
            RegisterExtComponentReply=node.on_reply, ArmingCheckRequest=node.on_check
        )
        flight.t0 = t0 = time.monotonic()
        node.start(t0)
        while (now := time.monotonic()) - t0 < program.fly_s:
            node.tick(now)
            time.sleep(TICK_S)
        flight.recorder.on_message.clear()
        if program.tail_s > 0:
            time.sleep(program.tail_s)
        flight.stop_recording()
        notes = [*node.notes, (time.monotonic(), f"{node.answered} arming checks answered")]
        summary = flight.summary(program.name, stem, notes)
    flight.write(out, stem, summary)
    return summary


def stamp_shifts(samples: list[tuple[str, float, Any]], start_us: int) -> dict[str, int]:
    """What ``send_plan`` adds to the stamps of each topic: a topic's first stamped message
    (topic, offset, sample) is stamped with its sending time, ``start_us`` plus its offset, and
    the topic's later ones keep their distance from it. Per topic, since a node's topics need
    not share one clock: fuzzoff's streams stamp the keep-alive with a clock of its own (lagging,
    stuck, jumping: PX4 ages an OffboardControlMode by its stamp, and the gate model takes the
    first as fresh) and the rest with the sending time."""
    shifts: dict[str, int] = {}
    for topic, offset, sample in samples:
        stamp: int = getattr(sample, "timestamp", 0)
        if stamp and topic not in shifts:
            shifts[topic] = start_us + round(offset * 1e6) - stamp
    return shifts


def readdressed(sample: Any, shift: int, target_system: int | None) -> Any:
    """``sample`` as ``send_plan`` sends it: stamps moved by ``shift`` (0 stays 0: PX4 stamps
    it on receipt), a command addressed to a system (not 0, all) sent to ``target_system``."""
    addressed: int = getattr(sample, "target_system", 0)
    if target_system is not None and addressed:
        sample.target_system = target_system
    for name in ("timestamp", "timestamp_sample"):
        stamp: int = getattr(sample, name, 0)
        if stamp:
            setattr(sample, name, max(1, stamp + shift))
    return sample


def send_plan(
    participant: DomainParticipant,
    plan: ReplayPlan,
    now: Callable[[], float] = time.monotonic,
    wait_until: Callable[[float], None] | None = None,
    target_system: int | None = None,
    writers: dict[str, Publisher] | None = None,
) -> list[float]:
    """Send ``plan``'s messages at their offsets from ``now()`` at the start; the ``now()``
    each one went out. Each ``timestamp`` (and ``timestamp_sample``) is moved onto this host's
    clock, keeping its distance from its topic's first stamped message's as recorded
    (``stamp_shifts``): a sender whose clock ran with the recording stamps the sending time,
    one whose stamps lagged or jumped (PX4 ages an OffboardControlMode by its stamp) still
    does. A command goes to ``target_system`` (the PX4 it is sent to: ``MAV_SYS_ID``,
    ``PX4_INSTANCE`` + 1), as ``fuzzoff replay --to`` readdresses MAVLink (``readdressed``).
    ``writers``: writers made (and matched by PX4's bridge) before, by ROS 2 topic; a topic
    without one gets a new writer here (whose first messages go out before PX4's reader may
    have matched it: a node that makes a publisher and writes at once, OFB208)."""
    publishers: dict[str, tuple[BridgeTopic, Publisher]] = {}
    samples = []
    for message in plan.messages:
        if message.topic not in publishers:
            topic = BridgeTopic(message.message, message.topic, message.msgdef)
            made = (writers or {}).get(message.topic)
            publishers[message.topic] = (topic, made or Publisher(participant, topic))
        topic, publisher = publishers[message.topic]
        samples.append((message.offset_s, publisher, idl_type(topic).deserialize(message.data)))
    wait = wait_until or (lambda t: time.sleep(max(0.0, t - now())))
    start = now()
    shifts = stamp_shifts(
        [
            (m.topic, m.offset_s, sample)
            for m, (_, _, sample) in zip(plan.messages, samples, strict=True)
        ],
        now_us(),
    )
    sent = []
    for message, (offset, publisher, sample) in zip(plan.messages, samples, strict=True):
        wait(start + offset)
        publisher.write(readdressed(sample, shifts.get(message.topic, 0), target_system))
        sent.append(now())
    return sent


def replay(
    release: str,
    out: Path,
    stem: str,
    plan: ReplayPlan,
    log: Log = print,
    params: dict[str, float] | None = None,
) -> dict[str, Any]:
    """Send a recorded bag's ``/fmu/in`` messages to PX4 at their recorded times (``send_plan``:
    the stamps on this host's clock, as the sending node stamped them)."""
    with BridgeFlight(release, None, log, params=params) as flight:
        flight.wait_ready()
        flight.record()
        time.sleep(LEAD_S)
        node_participant = DomainParticipant(0)
        flight.t0 = t0 = time.monotonic()
        send_plan(node_participant, plan, target_system=flight.px4.sysid)
        time.sleep(REPLAY_TAIL_S)
        flight.stop_recording()
        note = f"replayed {len(plan.messages)} messages of {plan.source}"
        summary = flight.summary("replay", stem, [(t0, note)])
    flight.write(out, stem, summary)
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fuzzoff.sitl.ros2.flight")
    parser.add_argument("program", help=f"one of {', '.join(PROGRAMS)}, or a replay plan (.json)")
    parser.add_argument("release", help="a bundle with the bridge (1.16.2-ros2) or a build folder")
    parser.add_argument("stem", help="the outputs' name")
    parser.add_argument("--vehicle", help="the SIH airframe (fuzzoff.sitl.airframes)")
    parser.add_argument("--param", action="append", default=[], help="NAME=VALUE, at boot")
    args = parser.parse_args(argv)
    params = {k: float(v) for k, _, v in (p.partition("=") for p in args.param)}
    out = Path(".")  # the caller's folder: netns binds it at its own path and enters it
    if args.program.endswith(".json"):
        plan = load_plan(Path(args.program))
        summary = replay(args.release, out, args.stem, plan, params=params)
    elif args.program in PROGRAMS:
        summary = fly(args.release, out, args.stem, PROGRAMS[args.program], vehicle=args.vehicle)
    else:
        parser.error(f"no program {args.program!r}")
    (out / f"{args.stem}.json").write_text(json.dumps(summary, indent=1, default=str) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
