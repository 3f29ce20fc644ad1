"""``fuzzoff fuzz --against sitl:RELEASE``: generated streams sent to a real PX4, beside the model.

The campaign draws MAVLink streams with the campaign's own Hypothesis strategies
(``fuzz.streams.scenarios`` for the release's profile, a multicopter, MAVLink: keep-alive
timing with gaps around the loss timeout, setpoint kinds, frames and masks, arms and switches
with and without a stream, leaving and disarming, ``COM_OF_LOSS_T``, ``COM_OBL_RC_ACT`` and
manual control present or not), keeping those with a switch to OFFBOARD and one of each shape
the gate can tell apart (``classify.shape``: each costs seconds of real time). Each one is written
with the tlog writer, as its reproducer will be, and sent to one PX4 booted for the campaign
(``bench.Bench``: put back to landed, disarmed, in Hold before each stream, restarted when it
cannot be) exactly as ``fuzzoff replay --to`` sends it. The exchange is judged as ``fuzzoff
sitl`` judges a run (``verdict.compare``: PX4's ULog beside the gate model run on the tlog).

A stream the host did not send as meant (``delivery``) is *noise*, not PX4 behaviour. A stream
PX4 and the model disagree on is sent once more (*confirmed* when the same disagreement comes
back), then shrunk by sending simpler variants (``variants``, a few runs at most), and saved as
a reproducer in the campaign's format with an ``against`` block: what PX4 did, what the model
predicted, the exchange's tlog and ULog beside it. ``fuzzoff replay NAME.expected.json --to
udp:127.0.0.1:14580`` sends it to a running PX4 again.

``transport="ros2"`` (a bundle with the ROS 2 bridge): the campaign moves into a private network
namespace (``ros2.netns.enter``), the streams are drawn as a ROS 2 companion publishes them
(``OffboardControlMode``, the setpoint topics, ``VehicleCommand``), sent over DDS through the
Micro XRCE-DDS Agent (``ros2.bench.BridgeBench``), recorded as a bag (``ros2.recorder``), and
judged as ``sitl run --transport ros2`` judges a flight (``ros2.verdict.compare``: the bag's
times put on PX4's clock as ``lint --with`` puts them). A reproducer is the MCAP stream as any
ROS 2 reproducer, with the exchange's bag folder (``NAME.px4-mcap``) beside it; ``fuzzoff sitl
replay NAME.expected.json --transport ros2`` sends its stream over DDS to a fresh PX4 again, with
the setup's parameters set at boot.
"""

from __future__ import annotations

import contextlib
import json
import shutil
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import field, replace
from pathlib import Path
from typing import Any, Literal

from fuzzoff import events as ev
from fuzzoff.bridge import BridgeError
from fuzzoff.config import Settings
from fuzzoff.fuzz import recordings
from fuzzoff.fuzz.reproducers import save, setup_for
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import px4_profile_for
from fuzzoff.recording import SourceError
from fuzzoff.releases import PX4Profile
from fuzzoff.sitl import airframes, bundle, delivery
from fuzzoff.sitl.bench import Bench, LiveRun
from fuzzoff.sitl.classify import edge_note, health_refusals, own_changes, shape, signature
from fuzzoff.sitl.driver import NAV_LOITER
from fuzzoff.sitl.link import COMPANION_SYSID, LinkError
from fuzzoff.sitl.run import load_plan
from fuzzoff.sitl.truth import read_truth, sim_stalled
from fuzzoff.sitl.variants import variants
from fuzzoff.sitl.verdict import Item, Verdict, compare

Transport = Literal["mavlink", "ros2"]

Status = Literal["agree", "differ", "outside", "noise", "failed"]
Log = Callable[[str], None]
DEFAULT_BUDGET_S = 300.0
SHRINK_RUNS = 4
"""Live runs a disagreement may take to shrink (after the one that confirms it)."""
LOSS_ITEMS = frozenset({"offboard loss", "loss time", "failsafe action", "automatic return"})
OWN_CHANGE_SLACK_S = 0.1
"""A change PX4 made by itself this soon after a disagreement still comes first (the verdict
dates a loss by PX4's flag, the ULog's vehicle_status follows)."""
CONFIRM_TRIES = 2
"""Sends to confirm a disagreement when a try cannot tell (noise, or not run)."""
START_LEAD_S = 0.0001
"""The starting status comes this long before the stream's first message."""
REPRODUCER_PREFIX = "px4"
"""Reproducer names start ``px4-``: a live disagreement, not a property of the model."""


@dataclass(slots=True)
class AgainstConfig:
    build: bundle.Build
    instance: int = 0
    vehicle: str = airframes.DEFAULT
    """The SIH airframe PX4 flies (``airframes.AIRFRAMES``: ``sitl run --vehicle``)."""
    budget_s: float | None = DEFAULT_BUDGET_S
    examples: int | None = None
    seed: int = 0
    shrink_runs: int = SHRINK_RUNS
    settings: Settings = field(default_factory=Settings)
    save_dir: Path | None = None
    """None: no reproducer saved (``--no-save``)."""
    transport: Transport = "mavlink"
    """``ros2``: the streams go over PX4's ROS 2 bridge (DDS), in a private network namespace."""

    @property
    def profile(self) -> PX4Profile:
        return px4_profile_for(self.build.profile_release)

    @property
    def judged_as(self) -> str:
        """The vehicle type the streams are drawn for and the model judges (``mc``, ``fw``...)."""
        return airframes.airframe_for(self.vehicle).fuzzoff_vehicle


@dataclass(slots=True)
class Example:
    """One stream sent to PX4 and its verdict."""

    index: int
    scenario: Scenario
    """The stream as generated (or simplified), without the starting status."""
    status: Status
    verdict: Verdict | None = None
    delivery: delivery.Delivery | None = None
    reason: str = ""
    """Why it is noise or failed."""
    edge: str | None = None
    """A loss disagreement on a gap within one check period of the loss timeout (PX4's
    outcome there depends on the phase of its 10 Hz check)."""
    tlog: Path | None = None
    ulog: Path | None = None
    first_sent_px4: float | None = None
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)
    purpose: str = "search"
    """``search``, ``confirm`` or ``shrink``."""

    @property
    def differing(self) -> list[Item]:
        return [] if self.verdict is None else [i for i in self.verdict.items if i.agree is False]


@dataclass(slots=True)
class Disagreement:
    found: Example
    confirmed: bool | None
    """None: the second run could not tell (noise or failed)."""
    kept: Example
    """The simplest run that still showed the disagreement (``found`` when not shrunk)."""
    shrunk_by: list[str] = field(default_factory=list)
    shrink_runs: int = 0
    reproducer: Path | None = None
    second: Example | None = None
    """The run that tried to confirm it (its evidence is kept when it did not)."""
    seen_again: list[int] = field(default_factory=list)
    """Later streams of the search that showed the same disagreement (not followed up)."""


@dataclass(slots=True)
class AgainstResult:
    config: AgainstConfig
    examples: list[Example] = field(default_factory=list)
    """Every run: the search's and the follow-ups' (``purpose``)."""
    disagreements: list[Disagreement] = field(default_factory=list)
    seconds: float = 0.0
    boots: list[float] = field(default_factory=list)
    same_shape: int = 0
    """Streams drawn but not sent: the gate could not tell them from one already sent."""
    stopped: str | None = None
    """Why the campaign ended early (PX4 could not be run), None when it ran its course."""

    @property
    def search(self) -> list[Example]:
        return [e for e in self.examples if e.purpose == "search"]

    def outcomes(self) -> Counter[str]:
        """PX4's outcomes by kind over the search's streams (its side of each verdict item)."""
        tally: Counter[str] = Counter()
        for example in self.search:
            if example.verdict is None or example.status == "noise":
                continue
            for item in example.verdict.items:
                key = _outcome_key(item)
                if key:
                    tally[key] += 1
        return tally


def _outcome_key(item: Item) -> str | None:
    if item.what == "recorded vs model":
        return None
    if item.what == "loss time":
        return "offboard loss flagged by PX4"
    return f"{item.what}: {item.px4}"


# ---------------------------------------------------------------------------------------------
# the stream as sent


def with_start(scenario: Scenario) -> Scenario:
    """``scenario`` with the autopilot's status at its start: disarmed in Hold, where the bench
    puts PX4 (the model's own start: disarmed, not in OFFBOARD). In the tlog it is PX4's
    HEARTBEAT before the stream, from which ``replay --to`` brings PX4 there first."""
    first = scenario.events[0].t if scenario.events else 0.0
    vehicle = "1" if scenario.transport == "mavlink" else ""  # a ROS 2 namespace: none
    if vehicle == "" and first < START_LEAD_S:
        # a bag's log times cannot go below its start: the stream moves, its stamps do not
        shift = START_LEAD_S - first
        moved = tuple(replace(e, t=round(e.t + shift, 6)) for e in scenario.events)
        scenario, first = replace(scenario, events=moved), START_LEAD_S
    start = ev.VehicleStatus(
        t=first - START_LEAD_S,
        vehicle=vehicle,
        nav_state=NAV_LOITER,
        mode="AUTO_LOITER",
        armed=False,
    )
    return replace(scenario, events=(start, *scenario.events))


def _has_switch(scenario: Scenario) -> bool:
    return any(isinstance(e, ev.Command) and e.is_offboard_switch for e in scenario.events)


def describe_item(item: Item) -> str:
    return f"{item.what} at {item.t:.3f} s: PX4 {item.px4}; model {item.model}"


# ---------------------------------------------------------------------------------------------
# the campaign


class _Stop(BaseException):
    """The budget is spent (a BaseException, so Hypothesis does not take it for a failure)."""


class Campaign:
    def __init__(self, config: AgainstConfig, log: Log) -> None:
        self.config = config
        self.log = log
        self.result = AgainstResult(config)
        self.started = 0.0
        quad = config.vehicle == airframes.DEFAULT  # PX4's own default: nothing to check
        env = {} if quad else airframes.boot_env(config.build, config.vehicle)
        fixes = airframes.fixes_for(airframes.airframe_for(config.vehicle), config.build.release)
        bench: type[Bench] = Bench
        if config.transport == "ros2":
            from fuzzoff.sitl.ros2.bench import BridgeBench

            bench = BridgeBench
        lands = config.judged_as != "fw"
        self.bench = bench(config.build, config.instance, log, env, lands, fixes)
        self.known: dict[tuple[str, str, str], Disagreement] = {}
        """Disagreements followed up, by signature (a confirmed one is not followed again)."""
        self.error: Exception | None = None
        """An error of fuzzoff's own that stopped the search (raised once it is over)."""
        self.work = Path(tempfile.gettempdir())
        """The streams and exchanges of the runs (a temporary folder while ``run`` runs)."""

    # -- budget

    def elapsed(self) -> float:
        return time.monotonic() - self.started

    def spent(self) -> bool:
        budget = self.config.budget_s
        return budget is not None and self.elapsed() >= budget

    # -- the whole campaign

    def run(self) -> AgainstResult:
        self.started = time.monotonic()
        self.work = Path(tempfile.mkdtemp(prefix="fuzzoff-against-"))
        try:
            self.bench.start()
            self._search()
        except LinkError as exc:
            self.result.stopped = str(exc)
        except bundle.BundleError as exc:
            self.result.stopped = str(exc)
        finally:
            self.bench.close()
            if self.config.transport == "ros2":
                self.bench.shutdown()  # type: ignore[attr-defined]  # BridgeBench's DDS side
            self.result.boots = list(self.bench.boots)
            self.result.seconds = self.elapsed()
            if self.error is None:
                shutil.rmtree(self.work, ignore_errors=True)
            else:  # what the stream that met fuzzoff's error sent and recorded
                self.log(f"the runs' files are kept in {self.work}")
        return self.result

    def _search(self) -> None:
        from hypothesis import Phase, given, reject, seed, settings
        from hypothesis import strategies as st

        from fuzzoff.fuzz.campaign import PROFILE_CI, _hypothesis_storage
        from fuzzoff.fuzz.streams import scenarios

        shapes: set[tuple[object, ...]] = set()

        def one(scenario: Scenario) -> None:
            if not _has_switch(scenario):
                reject()  # nothing of the offboard gate to see: not worth a live run
            if shape(scenario) in shapes:
                self.result.same_shape += 1
                reject()  # PX4's gate cannot tell it from one already sent
            shapes.add(shape(scenario))
            if self.spent():
                raise _Stop
            try:
                self.searched(self.send(scenario, "search"))
            except (LinkError, bundle.BundleError) as exc:  # PX4 cannot be run any more
                self.result.stopped = str(exc)
                raise _Stop from None
            except Exception as exc:
                # fuzzoff's own error: raised as it is after the search. Hypothesis would run
                # the stream again to confirm a failure, which now rejects it as a shape
                # already sent, and report only "Unreliable assumption" (FlakyFailure)
                self.error = exc
                raise _Stop from None

        strategy: st.SearchStrategy[Scenario] = scenarios(
            self.config.profile, self.config.judged_as, self.config.transport
        )
        test = given(strategy)(one)
        test = settings(
            settings.get_profile(PROFILE_CI),
            max_examples=self.config.examples or 10**6,
            phases=(Phase.generate,),
        )(test)
        test = seed(self.config.seed)(test)
        with _hypothesis_storage(), contextlib.suppress(_Stop):
            test()
        if self.error is not None:
            raise self.error

    def searched(self, example: Example) -> None:
        """Follow a disagreement of the search up, unless it was confirmed before (then it is
        counted against the first one, not confirmed and shrunk again)."""
        if example.status != "differ":
            return
        again = self.known.get(signature(example.differing[0]))
        if again is not None:
            again.seen_again.append(example.index)
        else:
            self.follow_up(example)

    # -- one stream

    def send(self, scenario: Scenario, purpose: str) -> Example:
        """Send ``scenario`` to PX4 and judge what it did."""
        index = len(self.result.examples) + 1
        example = Example(index, scenario, "failed", purpose=purpose)
        self.result.examples.append(example)
        started = time.monotonic()
        stem = self.work / f"{index:04d}"
        try:
            self._send(example, stem)
        finally:
            example.seconds = time.monotonic() - started
            self.log(_line(example))
        return example

    def _exchange(self, example: Example, stem: Path) -> LiveRun:
        """Send the stream as its transport goes (PX4 prepared first): the run."""
        live = with_start(example.scenario)
        setup = setup_for(example.scenario)
        if self.config.transport == "ros2":
            from fuzzoff.sitl.ros2.bench import BridgeBench
            from fuzzoff.sitl.ros2.replay import ReplayError, plan_from_bag

            assert isinstance(self.bench, BridgeBench)
            stream = recordings.write(live, stem.with_suffix(".stream-bag"), "rosbag2")
            try:
                bag_plan = plan_from_bag(stream, self.config.build.profile_release)
            except ReplayError:
                raise LinkError("nothing to send: the stream has no /fmu/in message") from None
            example.notes += self.bench.prepare(setup.params, setup.manual_control)
            return self.bench.send_bag(
                bag_plan, setup.params, stem.with_suffix(".px4-mcap"), stem.with_suffix(".px4.ulg")
            )
        recordings.write(live, stem.with_suffix(".stream.tlog"), "tlog")
        plan = load_plan(stem.with_suffix(".stream.tlog"))
        example.notes += self.bench.prepare(setup.params, setup.manual_control)
        return self.bench.send(
            plan, setup.params, stem.with_suffix(".px4.tlog"), stem.with_suffix(".px4.ulg")
        )

    def _judge(self, run: LiveRun, params: dict[str, float]) -> Verdict:
        release = self.config.build.profile_release
        if self.config.transport == "ros2":
            from fuzzoff.sitl.ros2 import verdict as ros2_verdict

            if run.ulog is None:
                raise SourceError(run.tlog, "PX4 wrote no ULog for this stream")
            return ros2_verdict.compare(run.tlog, release, run.ulog, params, self.config.judged_as)
        return compare(run.tlog, release, run.ulog, params, COMPANION_SYSID, self.config.judged_as)

    def _send(self, example: Example, stem: Path) -> None:
        setup = setup_for(example.scenario)
        try:
            run = self._exchange(example, stem)
        except LinkError as exc:
            example.reason = str(exc)
            if self.bench.session is None:
                raise
            return
        example.notes += run.notes
        example.tlog, example.ulog = run.tlog, run.ulog
        example.first_sent_px4 = run.sent[0] if run.sent else None
        example.delivery = delivery.check(run.meant, run.sent)
        try:
            truth = None if run.ulog is None else read_truth(run.ulog)
            stalled = None if truth is None else sim_stalled(truth, max(run.meant, default=0.0))
            if stalled is not None:  # main's SIH: nothing to judge (docs/sitl.md)
                example.reason = stalled
                return
            verdict = self._judge(run, setup.params)
        except SourceError as exc:  # PX4 killed while writing its log, say
            example.reason = f"the run's recordings cannot be judged: {exc.line()}"
            return
        except BridgeError as exc:  # a ROS 2 run's bag and ULog cannot be put on one clock
            example.reason = f"the run's recordings cannot be judged: {exc}"
            return
        verdict.items = [i for i in verdict.items if i.t >= run.recording_from]
        example.verdict = verdict
        if verdict.problems and not verdict.items:
            example.reason = "; ".join(verdict.problems)
            return
        own = [] if truth is None else own_changes(truth, run.recording_from)
        own += [] if truth is None else health_refusals(truth, run.recording_from)
        own.sort(key=lambda change: change.t)
        first = min((i.t for i in example.differing), default=None)
        before = [c for c in own if first is not None and c.t <= first + OWN_CHANGE_SLACK_S]
        if not example.differing:
            example.status = "agree"
        elif before:
            example.status = "outside"
            example.reason = f"{before[0].describe()}: the gate model does not model that"
        elif not example.delivery.faithful:
            example.status = "noise"
            example.reason = f"the host sent the stream {example.delivery.describe()}"
        else:
            example.status = "differ"
            if any(i.what in LOSS_ITEMS for i in example.differing):
                example.edge = edge_note(example.scenario)

    # -- a disagreement

    def stream_time(self, example: Example, item: Item) -> float:
        """PX4's time of ``item`` as a time of the stream (its first companion message)."""
        ros2 = self.config.transport == "ros2"
        first = next(
            (
                e.t
                for e in example.scenario.events
                if (e.origin == "sent" if ros2 else isinstance(e, ev.Command | ev.MavlinkTarget))
            ),
            0.0,
        )
        return first + item.t - (example.first_sent_px4 or item.t)

    def follow_up(self, found: Example) -> None:
        """Confirm ``found`` with a second run, shrink it, save it."""
        target = signature(found.differing[0])
        confirmed: bool | None = None
        again = None
        for _ in range(CONFIRM_TRIES):
            again = self.send(found.scenario, "confirm")
            if again.status not in ("noise", "failed"):
                confirmed = target in {signature(i) for i in again.differing}
                break
        case = Disagreement(found, confirmed, found, second=again)
        self.result.disagreements.append(case)
        if confirmed:
            self.known[target] = case
            self._shrink(case, target)
        self._save(case)

    def _shrink(self, case: Disagreement, target: tuple[str, str, str]) -> None:
        tried: set[str] = set()
        while case.shrink_runs < self.config.shrink_runs and not self.spent():
            kept = case.kept
            item = next(i for i in kept.differing if signature(i) == target)
            t = self.stream_time(kept, item)
            step = next(((n, s) for n, s in variants(kept.scenario, t) if n not in tried), None)
            if step is None:
                return
            name, simpler = step
            tried.add(name)
            case.shrink_runs += 1
            run = self.send(simpler, "shrink")
            if run.status == "differ" and target in {signature(i) for i in run.differing}:
                case.kept = run
                case.shrunk_by.append(name)

    def _save(self, case: Disagreement) -> None:
        directory = self.config.save_dir
        kept = case.kept
        if directory is None or kept.verdict is None:
            return
        problems = [describe_item(i) for i in kept.differing]
        path = save(
            REPRODUCER_PREFIX,
            with_start(kept.scenario),
            problems,
            directory,
            base=self.config.settings,
        )
        name = path.name[: -len(".expected.json")]
        runs = [(kept, ".px4")]
        if not case.confirmed and case.second is not None:
            runs.append((case.second, ".second.px4"))
        evidence = {}
        exchange = "-mcap" if self.config.transport == "ros2" else ".tlog"
        for run, infix in runs:
            for source, suffix in ((run.tlog, exchange), (run.ulog, ".ulg")):
                if source is None or not source.exists():
                    continue
                target = directory / f"{name}{infix}{suffix}"
                if source.is_dir():  # a bag folder
                    shutil.rmtree(target, ignore_errors=True)
                    shutil.copytree(source, target)
                else:
                    shutil.copyfile(source, target)
                evidence[infix + suffix] = f"{name}{infix}{suffix}"
        spec = json.loads(path.read_text())
        spec["property"] = None  # nothing the model alone can check again: PX4 must answer
        spec["against"] = against_block(self.config, case, evidence)
        path.write_text(json.dumps(spec, indent=2) + "\n")
        case.reproducer = path


def against_block(
    config: AgainstConfig, case: Disagreement, evidence: dict[str, str]
) -> dict[str, Any]:
    """The ``against`` object of a live disagreement's reproducer."""
    kept = case.kept
    port = 14580 + config.instance
    bag = config.transport == "ros2"
    exchange = "-mcap" if bag else ".tlog"
    replay = (
        f"fuzzoff sitl replay NAME.expected.json --transport ros2 --release {config.build.release}"
        if bag
        else f"fuzzoff replay NAME.expected.json --to udp:127.0.0.1:{port}"
    )
    key = "exchange_bag" if bag else "exchange_tlog"
    return {
        "px4": config.build.release,
        "transport": config.transport,
        "differ": [i.to_json() for i in kept.differing],
        "confirmed": case.confirmed,
        "shrunk_by": case.shrunk_by,
        "edge": kept.edge,
        "delivery": None if kept.delivery is None else kept.delivery.to_json(),
        key: evidence.get(".px4" + exchange),
        "px4_ulog": evidence.get(".px4.ulg"),
        "second_run": None
        if case.second is None or case.confirmed
        else {
            "status": case.second.status,
            "reason": case.second.reason or None,
            "differ": [i.to_json() for i in case.second.differing],
            key: evidence.get(".second.px4" + exchange),
            "px4_ulog": evidence.get(".second.px4.ulg"),
        },
        "replay": replay,
    }


def _line(example: Example) -> str:
    s = example.scenario
    params = ", ".join(f"{k}={v:g}" for k, v in sorted(s.params.items()))
    head = f"{example.purpose} {example.index}: {len(s.events)} events over {s.duration:.1f} s" + (
        f" ({params})" if params else ""
    )
    if example.verdict is None:
        return f"{head}: not run: {example.reason}"
    items = [f"{i.what} {i.px4}" for i in example.verdict.items if i.what != "loss time"]
    what = "; ".join(items) or "nothing to compare"
    verdict = example.status.upper() if example.status != "agree" else "agree"
    extra = f" ({example.reason})" if example.reason else ""
    return f"{head}: {what} -> {verdict}{extra} [{example.seconds:.0f} s]"


def run_against(config: AgainstConfig, log: Log) -> AgainstResult:
    return Campaign(config, log).run()
