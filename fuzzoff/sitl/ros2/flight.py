"""One flight over PX4's ROS 2 bridge, run inside a private network namespace (``netns``).

PX4 (a bundle with ``uxrce_dds_client``) and the Micro XRCE-DDS Agent start together
(``run-px4.sh`` with ``PX4_AGENT``); a recorder subscribes to the example's inputs and to PX4's
outputs as soon as PX4 is on DDS; once PX4 says its pre-flight checks pass, the recording
starts and, ``LEAD_S`` later, the example node. When the plan is done the recording stops
first (as a user stops ``ros2 bag record`` before the node), then PX4, which closes its ULog.
Outputs, in the working folder: ``STEM-mcap/`` and ``STEM-sqlite3/`` (bag folders), ``STEM.ulg``
(PX4's log cut to the topics fuzzoff reads) and ``STEM.json`` (what happened, PX4's answers).

Run as ``python -m fuzzoff.sitl.ros2.flight`` by ``netns.run_flight``; needs cyclonedds.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cyclonedds.domain import DomainParticipant

from fuzzoff.formats.rosbag2.writer import Storage
from fuzzoff.sitl import bundle
from fuzzoff.sitl.ros2 import agent
from fuzzoff.sitl.ros2.bag import Recording, write_bag
from fuzzoff.sitl.ros2.dds import Publisher, RawReader
from fuzzoff.sitl.ros2.example import TICK_S, OffboardControl
from fuzzoff.sitl.ros2.names import RECEIVED, SENT, BridgeTopic, bridge_topic
from fuzzoff.sitl.ros2.programs import PROGRAMS, Program
from fuzzoff.sitl.trim import trim

READY_TIMEOUT_S = 90.0
LEAD_S = 0.5
"""The recording starts this long before the node (``ros2 bag record`` started first)."""
POLL_S = 0.002


@dataclass(slots=True)
class Watch:
    """What PX4 said last, decoded for the flight's own decisions and its summary."""

    status: dict[str, Any] = field(default_factory=dict)
    acks: list[dict[str, Any]] = field(default_factory=list)
    modes: list[tuple[float, int, int, bool]] = field(default_factory=list)
    """(monotonic s, nav_state, arming_state, failsafe) at each change"""


class Recorder:
    """Readers of every topic polled by one thread; each sample's bytes to the recording."""

    def __init__(self, participant: DomainParticipant, topics: list[BridgeTopic]) -> None:
        self.readers = [RawReader(participant, t) for t in topics]
        self.recording: Recording | None = None
        self.watch = Watch()
        self.error: BaseException | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5.0)

    def _loop(self) -> None:
        try:
            while not self._stop.is_set():
                for reader in self.readers:
                    reader.take(self._deliver)
                time.sleep(POLL_S)
        except BaseException as exc:  # reported by the flight, which stops
            self.error = exc

    def _deliver(self, topic: BridgeTopic, data: bytes, received_ns: int) -> None:
        if self.recording is not None:
            self.recording.add(topic, data, received_ns)
        if topic.message == "VehicleStatus":
            self._status(self._decode(topic, data))
        elif topic.message == "VehicleCommandAck":
            ack = self._decode(topic, data)
            self.watch.acks.append(
                {"t": time.monotonic(), "command": ack.command, "result": ack.result}
            )

    def _decode(self, topic: BridgeTopic, data: bytes) -> Any:
        return next(r for r in self.readers if r.topic == topic).decode(data)

    def _status(self, status: Any) -> None:
        self.watch.status = {
            "nav_state": status.nav_state,
            "arming_state": status.arming_state,
            "failsafe": status.failsafe,
            "pre_flight_checks_pass": status.pre_flight_checks_pass,
        }
        key = (status.nav_state, status.arming_state, bool(status.failsafe))
        if not self.watch.modes or self.watch.modes[-1][1:] != key:
            self.watch.modes.append((time.monotonic(), *key))

    def offered(self) -> dict[str, list[Any]]:
        return {r.topic.ros_topic: list(r.offered.values()) for r in self.readers if r.offered}


class AgentRestart:
    """Stops PX4's agent and starts a new one when the program says (``agent.py``)."""

    def __init__(self, program: Program, px4: bundle.Px4Process) -> None:
        self.program = program
        self.px4 = px4
        self.notes: list[tuple[float, str]] = []
        self.stopped_at: float | None = None
        self.new: subprocess.Popen[bytes] | None = None

    def step(self, now: float, armed_at: float | None) -> None:
        stop_after = self.program.agent_stop_after_arm_s
        if stop_after is None or armed_at is None or self.new is not None:
            return
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


def fly(release: str, out: Path, stem: str, program: Program, log: Any = print) -> dict[str, Any]:
    """Fly ``program`` on the bundle ``release``; what happened (the run's summary)."""
    plan, fly_s, tail_s = program.plan, program.fly_s, program.tail_s
    if "/" in release:  # a build folder (--px4-build)
        build = bundle.find_build(None, Path(release))
    else:
        build = bundle.find_build(release, None)
    env = {
        "PX4_AGENT": str(bundle.default_root() / "agent"),
        "PX4_PARAM_SDLOG_MODE": "2",
    }
    px4 = bundle.start(build, 0, env)
    summary: dict[str, Any] = {
        "recording": stem,
        "program": program.name,
        "release": build.release,
    }
    participant = DomainParticipant(0)
    received = [bridge_topic(build.profile_release, m) for m in RECEIVED]
    sent = [bridge_topic(build.profile_release, m) for m in SENT]
    recorder = Recorder(participant, sent + (received if program.topics == "all" else []))
    watcher = Recorder(participant, received) if program.topics != "all" else recorder
    restart = AgentRestart(program, px4)
    recorder.start()
    if watcher is not recorder:
        watcher.start()
    try:
        started = time.monotonic()
        while not watcher.watch.status.get("pre_flight_checks_pass"):
            if watcher.error is not None:
                raise watcher.error
            if not px4.alive() or time.monotonic() - started > READY_TIMEOUT_S:
                raise bundle.BundleError(
                    f"PX4 {build.release} not ready on DDS after {READY_TIMEOUT_S:.0f} s: "
                    + px4.console_tail()
                )
            time.sleep(0.1)
        log(f"PX4 {build.release} on DDS, ready {time.monotonic() - started:.1f} s after start")
        recording = Recording()
        if program.record_from_s is None:
            recorder.recording = recording
            time.sleep(LEAD_S)
        node_participant = DomainParticipant(0)
        by_message = {t.message: t for t in sent}
        node = OffboardControl(
            {t.message: Publisher(node_participant, t) for t in sent},
            plan,
            new_sink=lambda message: Publisher(node_participant, by_message[message]),
        )
        t0 = time.monotonic()
        tick = t0 + TICK_S
        while True:
            now = time.monotonic()
            restart.step(now, node.armed_at)
            if recorder.recording is None and now - t0 >= (program.record_from_s or 0.0):
                recorder.recording = recording
            if node.armed_at is not None and now - node.armed_at >= fly_s:
                break
            if now - t0 > fly_s + 30:
                break
            if now >= tick:
                node.tick(now)
                tick += TICK_S
            time.sleep(min(0.01, max(0.0, tick - time.monotonic())))
        if tail_s > 0:
            time.sleep(tail_s)
        recording.stop()
        if recorder.error is not None:
            raise recorder.error
        notes = sorted(node.notes + restart.notes)
        summary["notes"] = [(round(t - t0, 3), n) for t, n in notes]
        summary["modes"] = [(round(t - t0, 3), *rest) for t, *rest in watcher.watch.modes]
        summary["acks"] = [
            {**a, "t": round(a["t"] - t0, 3)} for a in watcher.watch.acks if a["t"] >= t0
        ]
        summary["offered"] = {k: [q._asdict() for q in v] for k, v in recorder.offered().items()}
    finally:
        restart.close()
        recorder.close()
        if watcher is not recorder:
            watcher.close()
        ulog = px4.stop()
        console = px4.console_tail(3)
    summary["console_tail"] = console
    summary["counts"] = {t.ros_topic: recording.count(t.ros_topic) for t in sent + received}
    storages: tuple[Storage, ...] = ("mcap", "sqlite3")
    for storage in storages:
        write_bag(out / f"{stem}-{storage}", recording.records, recorder.offered(), storage)
    if ulog is not None:
        trim(ulog, out / f"{stem}.ulg")
    px4.cleanup()
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fuzzoff.sitl.ros2.flight")
    parser.add_argument("program", choices=sorted(PROGRAMS))
    parser.add_argument("release", help="a bundle with the bridge (1.16.2-ros2) or a build folder")
    parser.add_argument("stem", help="the outputs' name")
    args = parser.parse_args(argv)
    out = Path(".")  # the caller's folder: netns binds it at its own path and enters it
    summary = fly(args.release, out, args.stem, PROGRAMS[args.program])
    (out / f"{args.stem}.json").write_text(json.dumps(summary, indent=1, default=str) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
