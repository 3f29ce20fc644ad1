"""The live campaign's bench over PX4's ROS 2 bridge (``fuzz --against sitl:R --transport ros2``).

``BridgeBench`` is ``fuzzoff.sitl.bench.Bench`` with the Micro XRCE-DDS Agent started beside
PX4 (``run-px4.sh`` with ``PX4_AGENT``; the bridge's namespace cleared, so the topics are
``/fmu/...`` whatever ``--instance``) and a DDS participant in the campaign's process. The
bench's own work stays on MAVLink, which the bridge bundles also run: putting PX4 back to
landed, disarmed, in Hold, its parameters, the joystick when a stream assumes manual control,
the logger switched on and off around each stream. The stream itself goes over DDS: the
scenario's ``/fmu/in`` messages (``OffboardControlMode``, the setpoints, ``VehicleCommand``) as
a bag holds them (``replay.plan_from_bag`` on the scenario written by the rosbag2 writer), sent
at their times by ``flight.send_plan``; the recorder (``recorder.Recorder``, the one of ``sitl
run --transport ros2``) writes what went over DDS, both ways, as the run's bag.

Everything here runs inside the private network namespace the campaign entered
(``netns.enter``); needs cyclonedds.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from cyclonedds.domain import DomainParticipant

from fuzzoff.sitl import bundle
from fuzzoff.sitl.bench import LOGGER_OPEN_S, STATUS_WAIT_S, Bench, LiveRun, Log, _wait_ready
from fuzzoff.sitl.link import LinkError
from fuzzoff.sitl.ros2 import agent
from fuzzoff.sitl.ros2.bag import Recording, write_bag
from fuzzoff.sitl.ros2.dds import Publisher
from fuzzoff.sitl.ros2.flight import READY_TIMEOUT_S, send_plan
from fuzzoff.sitl.ros2.names import RECEIVED, BridgeTopic, NamesError, bridge_topic
from fuzzoff.sitl.ros2.recorder import Recorder
from fuzzoff.sitl.ros2.replay import Plan
from fuzzoff.sitl.ros2.rover import ROVER_MESSAGES
from fuzzoff.sitl.run import TAIL_S
from fuzzoff.sitl.session import LOGGER_SETTLE_S
from fuzzoff.sitl.trim import trim

STREAMED = (
    "OffboardControlMode",
    "TrajectorySetpoint",
    "VehicleAttitudeSetpoint",
    "VehicleRatesSetpoint",
    "VehicleCommand",
    *ROVER_MESSAGES,
)
"""What a generated ROS 2 stream may publish (those the release defines are recorded)."""
MATCH_TIMEOUT_S = 10.0
"""How long the stream's writers may take to match PX4's bridge readers after a boot."""


def bridge_namespace(build: bundle.Build, instance: int) -> str:
    """The ROS 2 namespace PX4's rcS gives the bridge: none for instance 0, or where
    ``PX4_UXRCE_DDS_NS=""`` clears it (the 1.18 rcS); ``/px4_N`` for instance N on 1.16 and 1.17,
    whose rcS only takes a namespace that is not empty."""
    if instance == 0:
        return ""
    rcs = build.folder / "etc" / "init.d-posix" / "rcS"
    text = rcs.read_text(errors="replace") if rcs.exists() else ""
    return "" if "PX4_UXRCE_DDS_NS+x" in text else f"/px4_{instance}"


class BridgeBench(Bench):
    def __init__(
        self,
        build: bundle.Build,
        instance: int,
        log: Log = print,
        env: dict[str, str] | None = None,
        lands: bool = True,
        fixes: dict[str, float] | None = None,
    ) -> None:
        bridge = {"PX4_AGENT": str(bundle.default_root() / "agent"), "PX4_UXRCE_DDS_NS": ""}
        super().__init__(build, instance, log, {**(env or {}), **bridge}, lands, fixes)
        release = build.profile_release
        self.namespace = bridge_namespace(build, instance)
        self.streamed: dict[str, BridgeTopic] = {}
        """The stream's topic as a bag names it (``/fmu/in/...``) -> PX4's, in its namespace."""
        rover = "rover" in self.env.get("PX4_SIM_MODEL", "")
        for message in STREAMED:
            if message.startswith("Rover") and not rover:
                continue  # only a rover's streams publish them (not every release bridges them)
            try:
                plain = bridge_topic(release, message)
            except NamesError:
                continue  # not in this release (the rover setpoints before 1.17)
            self.streamed[plain.ros_topic] = bridge_topic(release, message, self.namespace)
        self.received = [bridge_topic(release, m, self.namespace) for m in RECEIVED]
        self.participant: DomainParticipant | None = None
        self.sender: DomainParticipant | None = None
        self.recorder: Recorder | None = None
        self.writers: dict[str, Publisher] = {}
        """One writer per topic for the whole campaign, as a node keeps its publishers: each
        matched by PX4's reader before a stream goes out (a new one would lose its first
        messages to DDS discovery)."""
        self.unmatched: list[str] = []

    def start(self) -> None:
        # each boot's agent on a port of its own: the agent of the PX4 just stopped may hold
        # its port for a moment (run-px4.sh stops it within 0.5 s of PX4), and a new agent
        # that cannot bind it exits ("bind error ... errno: 98"); PX4_UXRCE_DDS_PORT is the
        # client's port too (rcS, 1.16 and later)
        self.env["PX4_UXRCE_DDS_PORT"] = str(agent.PORT + len(self.boots) % 100)
        super().start()
        if self.participant is None:
            self.participant = DomainParticipant(0)
            self.sender = DomainParticipant(0)
            topics = [*self.streamed.values(), *self.received]
            self.recorder = Recorder(self.participant, topics)
            self.recorder.start()
            self.writers = {t.ros_topic: Publisher(self.sender, t) for t in self.streamed.values()}
        self._wait_on_dds()
        self._wait_matched()

    def _wait_on_dds(self) -> None:
        """Until PX4's status arrives over DDS (the agent and the bridge are up)."""
        assert self.recorder is not None and self.session is not None
        self.recorder.watch.status = {}
        started = time.monotonic()
        while not self.recorder.watch.status:
            if self.recorder.error is not None:
                raise LinkError(f"the DDS recorder failed: {self.recorder.error}")
            if time.monotonic() - started > READY_TIMEOUT_S:
                tail = self.session.px4.console_tail(3)
                raise bundle.BundleError(
                    f"PX4 {self.build.release}: no VehicleStatus over DDS after"
                    f" {READY_TIMEOUT_S:.0f} s (is the agent running?): {tail}"
                )
            time.sleep(0.1)

    def _wait_matched(self) -> None:
        """Until PX4's bridge (through the agent) has matched every writer: two readers each,
        the campaign's recorder and the agent's (a topic PX4 does not subscribe to stays at
        one, and is noted)."""
        deadline = time.monotonic() + MATCH_TIMEOUT_S
        while time.monotonic() < deadline:
            self.unmatched = [t for t, w in self.writers.items() if w.matched() < 2]
            if not self.unmatched:
                return
            time.sleep(0.1)
        self.log(f"PX4's bridge did not match the writers of {', '.join(self.unmatched)}")

    def shutdown(self) -> None:
        """The end of the campaign: PX4 and the DDS side."""
        self.close()
        if self.recorder is not None:
            self.recorder.close()
            self.recorder = None

    def send_bag(self, plan: Plan, params: dict[str, float], bag: Path, ulog: Path) -> LiveRun:
        """As ``Bench.send`` for a ROS 2 stream: ``plan`` over DDS (PX4 already prepared), what
        went over DDS in the bag folder ``bag`` (mcap), PX4's log of it in ``ulog``."""
        session = self.session
        if session is None or self.recorder is None or self.sender is None:
            raise LinkError("PX4 is not running")
        unknown = sorted({m.topic for m in plan.messages} - set(self.streamed))
        if unknown:  # a harness bug: the writer named a topic the bridge does not carry
            raise LinkError(f"PX4 {self.build.release} has no bridge topic {', '.join(unknown)}")
        plan = Plan(
            plan.source,
            tuple(replace(m, topic=self.streamed[m.topic].ros_topic) for m in plan.messages),
        )
        link = self._link()
        driver = self._driver()
        before = set(session.px4.ulogs())
        session.px4.command("logger", "on")
        deadline = time.monotonic() + LOGGER_OPEN_S
        while not set(session.px4.ulogs()) - before and time.monotonic() < deadline:
            driver.wait(0.1)
        notes: list[str] = []
        manual = link.view.manual_present
        recording = Recording()
        status_topic = next(t.ros_topic for t in self.received if t.message == "VehicleStatus")
        recording_from = link.clock.now()
        self.recorder.recording = recording
        try:
            driver.wait(LOGGER_SETTLE_S)
            # the model reads the starting mode from the bag's VehicleStatus (PX4 sends it at
            # each change and about once a second)
            deadline = time.monotonic() + STATUS_WAIT_S
            while time.monotonic() < deadline and not recording.count(status_topic):
                driver.wait(0.05)
            said = _wait_ready(link, driver)
            if said is not None:
                notes.append(f"PX4 was not ready to arm when the stream began (it said: {said})")

            def wait_until(t: float) -> None:
                link.sleep_until(t, driver.tick)

            sysid = session.px4.sysid
            sent = send_plan(self.sender, plan, link.clock.now, wait_until, sysid, self.writers)
            driver.wait(params.get("COM_OF_LOSS_T", 1.0) + TAIL_S)
        finally:
            recording.stop()
            self.recorder.recording = None
            session.px4.command("logger", "off")
            self._wait_closed(session)
        if self.recorder.error is not None:
            raise LinkError(f"the DDS recorder failed: {self.recorder.error}")
        write_bag(bag, recording.records, self.recorder.offered(), "mcap")
        fresh = sorted(set(session.px4.ulogs()) - before, key=lambda p: p.stat().st_mtime)
        kept = None
        if fresh:
            try:
                kept = trim(fresh[-1], ulog)
            except Exception as exc:  # pyulog raises bare exceptions on a damaged log
                notes.append(f"PX4's ULog of this stream cannot be read ({exc})")
            for path in fresh:
                path.unlink(missing_ok=True)
        else:
            notes.append("PX4 wrote no ULog for this stream")
        meant = [m.offset_s for m in plan.messages]
        return LiveRun(bag, kept, meant, sent, dict(params), manual, recording_from, notes)
