"""One pass over a recording: source events -> shared state -> gate model -> checks -> findings."""

from __future__ import annotations

import gc
import math
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path
from typing import Protocol, cast

from fuzzoff import releases
from fuzzoff.catalog import get_rule, sent_stream_rules
from fuzzoff.checks import CheckContext, load_all
from fuzzoff.checks.base import STREAM_TYPES, Check, StreamBatch
from fuzzoff.checks.whole_file import in_readable_part, recording_findings
from fuzzoff.config import Settings
from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
    SetPositionTargetLocal,
    StatusText,
    TrajectorySetpoint,
    VehiclePosition,
    VehicleStatus,
    Where,
    is_keepalive,
)
from fuzzoff.findings import (
    FileReport,
    FileStats,
    Finding,
    Report,
    RunStats,
    Severity,
    clip,
)
from fuzzoff.formats import SourceError, open_source, recordings_in
from fuzzoff.gate import GateModel, GateTransition
from fuzzoff.profiles import (
    DEFAULT_PX4,
    DEFAULT_VEHICLE,
    Profile,
    ProfileError,
    px4_profile_for,
)
from fuzzoff.recording import (
    PLOT_SAMPLE_S,
    PlotSamples,
    RecordingInfo,
    SourceProblem,
    add_sample,
    first_byte,
    path_text,
)
from fuzzoff.releases import PX4Profile
from fuzzoff.state import VehicleState
from fuzzoff.timeline import Timeline
from fuzzoff.type_mask import POSITION_BITS

Progress = Callable[[float], None]

BATCH_LIMIT = 1024
"""The longest run of stream messages held for the checks that take runs (bounded memory)."""

SHORT_RUNS = 4.0
"""Runs shorter than this on average go to the checks one message at a time (issue 31). A run
costs a copy of the state, a snapshot of the gate and a call into every check that takes runs,
which only pays where a run holds several messages: a companion's stream alone (a tlog, a bag,
an MCAP) runs for hundreds, but in a PX4 ULog the status, flags and positions fall between every
one or two logged setpoints (a ten-minute real log: 5.2k stream messages in 2.6k runs, judged
in 0.21 s one at a time against 0.28 s as runs). Which way a run goes changes nothing a check
reports (``on_batch`` equals ``on_event`` one message at a time: tests/test_batching.py)."""
RUN_AVERAGE_WEIGHT = 0.125
"""The newest run's weight in the running average of run lengths."""

YOUNG_COLLECTION_EVERY = 20_000
"""Allocations between two collections of the youngest generation while a recording is judged
(Python's default: 700). Events are freed by their reference counts, not by the collector, yet
each collection walks the young objects, and every tenth promotes survivors until a full
collection walks the whole heap (rosbags' type store, the catalog, the modules): about 0.45 s
of a 1M-message MCAP or ROS 1 lint. At this threshold such a lint has no full collection, and
at most this many cyclic garbage objects wait for one. Process-wide, as the collector is: two
threads linting at once may each restore the other's setting early, which costs only time."""


def resolve_profile(info: RecordingInfo, settings: Settings) -> Profile:
    """The user's choice wins; else what the recording says; else the defaults (OFB003)."""
    release = info.px4_version
    detected_px4: PX4Profile | None = None
    if release:
        try:
            detected_px4 = px4_profile_for(release)
        except ProfileError:
            detected_px4 = None
    by_branch = releases.for_branch(info.px4_branch) if release else None
    note = None
    if by_branch is not None and detected_px4 in (by_branch.name, by_branch.reports_as):
        detected_px4 = by_branch.name  # type: ignore[assignment]  # a record's name is one
    elif detected_px4 is not None and settings.px4 is None:
        note = _reported_alike_note(releases.get(detected_px4), info.px4_branch)
    fallback = DEFAULT_PX4
    if info.px4_candidates and DEFAULT_PX4 not in info.px4_candidates:
        fallback = px4_profile_for(info.px4_candidates[-1])  # the newest the recording fits
    px4 = settings.px4 or detected_px4 or fallback
    vehicle = settings.vehicle or info.vehicle_type or DEFAULT_VEHICLE
    return Profile(
        px4=px4,
        vehicle=vehicle,
        px4_detected=settings.px4 is not None or detected_px4 is not None,
        vehicle_detected=settings.vehicle is not None or info.vehicle_type is not None,
        px4_release=release,
        px4_forced=settings.px4 is not None,
        vehicle_forced=settings.vehicle is not None,
        px4_note=note,
    )


def _reported_alike_note(release: releases.Release, branch: str | None) -> str | None:
    """Where another record's builds report the same version (main reports 1.18.0 beta): which
    one was assumed, and why."""
    alike = releases.reported_alike(release)
    if not alike:
        return None
    others = " and ".join(r.name for r in alike)
    named = f" ({branch} says neither)" if branch else ""
    other = alike[0].name
    return (
        f"{others} reports it too, no branch recorded{named}: {release.name} assumed, "
        f"--px4 {other} for a build of {other}"
    )


NOTE_LIMIT = 5000
"""Text messages, commands and acks a timeline keeps per vehicle (a recording may flood them)."""
SAMPLE_S = PLOT_SAMPLE_S


class VehicleRun:
    """Shared state, gate model and checks for one vehicle of one recording."""

    def __init__(
        self,
        vehicle: str,
        profile: Profile,
        settings: Settings,
        info: RecordingInfo,
        timeline: Timeline | None,
        *,
        batching: bool = True,
    ) -> None:
        self.state = VehicleState(
            mode_recorded="vehicle_status" in info.kinds,
            own_system=int(vehicle) if vehicle.isdecimal() else None,
        )
        stream = info.stream_recorded
        self.gate = GateModel(profile, settings.params, vehicle, stream_recorded=stream)
        self.ctx = CheckContext(
            profile=profile,
            settings=settings,
            info=info,
            vehicle=vehicle,
            state=self.state,
            gate=self.gate,
            stream_recorded=stream,
        )
        self.offboard_seen = False
        """Only kept without a recorded stream: did the vehicle show OFFBOARD, or was it asked
        to switch there (then the stream rules would have had something to judge)?"""
        self._watch_offboard = not stream
        self.checks = [cls(self.ctx) for cls in load_all() if cls.wanted(self.ctx)]
        self.handlers: dict[type, list[Callable[[Event], None]]] = {}
        self.batched = [c for c in self.checks if batching and _takes_runs(c)]
        """Checks that take stream messages: each gets them as runs (``StreamBatch``)."""
        self._wants = [
            (check.subscriptions, check.on_event, check in self.batched) for check in self.checks
        ]
        self._takers = [check.on_batch for check in self.batched]
        self._batch: StreamBatch | None = None
        self._one_by_one: dict[type, list[Callable[[Event], None]]] = {}
        """Per stream class: ``on_event`` of the checks that take runs, for short runs."""
        self._run_length = 0
        """Stream messages since the last other event."""
        self._average_run = SHORT_RUNS
        """Running average of ``_run_length`` at each other event (``SHORT_RUNS``)."""
        self.timeline = timeline
        self.last_t = 0.0

    def _handlers_for(self, cls: type) -> list[Callable[[Event], None]]:
        handlers = self.handlers.get(cls)
        if handlers is None:
            stream = cls in STREAM_TYPES
            handlers = [
                h
                for wants, h, runs in self._wants
                if issubclass(cls, wants) and not (runs and stream)
            ]
            self.handlers[cls] = handlers
        return handlers

    def _one_by_one_for(self, cls: type) -> list[Callable[[Event], None]]:
        handlers: list[Callable[[Event], None]] = [
            c.on_event for c in self.batched if issubclass(cls, c.subscriptions)
        ]
        self._one_by_one[cls] = handlers
        return handlers

    def _flush(self) -> None:
        """Hand the open run to the checks that take stream messages (before anything that
        changes state)."""
        batch = self._batch
        if batch is None:
            return
        self._batch = None
        ctx = self.ctx
        live = ctx.state, ctx.gate
        ctx.state, ctx.gate = batch.state, batch.gate
        try:
            for on_batch in self._takers:
                on_batch(batch)
        finally:
            ctx.state, ctx.gate = live

    def _dispatch(self, event: Event) -> None:
        for handler in self._handlers_for(type(event)):
            handler(event)

    def _transitions(self, transitions: list[GateTransition]) -> None:
        for tr in transitions:
            if self.timeline is not None:
                self.timeline.transitions.append(tr)
            self._dispatch(tr)

    def feed(self, event: Event) -> None:
        """The hot path: runs once per event of a recording, so it is kept flat.

        Stream messages also join the open run for the checks that take runs (while runs are
        short, ``SHORT_RUNS``, they go to those checks' ``on_event`` at once instead); the run
        is handed over before any other event, before a gate transition, and before a change of
        the declared control mode, so that it never spans a change of what checks read."""
        cls = type(event)
        stream = cls in STREAM_TYPES
        if not stream:
            self._flush()
            if self._run_length:
                average = self._average_run
                self._average_run = average + (self._run_length - average) * RUN_AVERAGE_WEIGHT
                self._run_length = 0
        self.last_t = event.t
        state = self.state
        state.update(event)
        gate = self.gate
        transitions = gate.feed(event)
        if transitions:
            self._flush()
            self._transitions(transitions)
        batch = self._batch
        if batch is not None and gate.in_offboard != batch.gate.in_offboard:
            self._flush()  # the prediction moved without a transition: the run saw it before
        if self.timeline is not None:
            self._record(event)
        if self._watch_offboard and (
            self.ctx.in_offboard or (isinstance(event, Command) and event.is_offboard_switch)
        ):
            self.offboard_seen = True
            self._watch_offboard = False
        handlers = self.handlers.get(cls)
        if handlers is None:
            handlers = self._handlers_for(cls)
        for handler in handlers:
            handler(event)
        if stream and self._takers:
            self._run_length += 1
            batch = self._batch
            if batch is None and self._average_run < SHORT_RUNS:
                one_by_one = self._one_by_one.get(cls)
                if one_by_one is None:
                    one_by_one = self._one_by_one_for(cls)
                for handler in one_by_one:
                    handler(event)
                return
            if batch is not None and state.declared_flag != batch.state.declared_flag:
                self._flush()
                batch = None
            if batch is None:
                batch = self._batch = StreamBatch(state, gate)
            batch.events.append(event)
            if len(batch.events) >= BATCH_LIMIT:
                self._flush()

    def _record(self, event: Event) -> None:
        assert self.timeline is not None
        if is_keepalive(event):
            self.timeline.keepalive.append(event.t)
        if isinstance(event, VehicleStatus):
            last = self.timeline.recorded_modes[-1] if self.timeline.recorded_modes else None
            entry = (event.t, event.nav_state, event.armed)
            if last is None or last[1:] != entry[1:]:
                self.timeline.recorded_modes.append(entry)
        if (event.origin == "sent" and not is_keepalive(event)) or event.kind.startswith("set_"):
            series = self.timeline.setpoint_kinds.setdefault(event.kind, [])
            if not series or event.t - series[-1] >= 0.05:
                series.append(event.t)
        if isinstance(event, NOTED):
            if len(self.timeline.notes) < NOTE_LIMIT:
                self.timeline.notes.append(event)
        elif isinstance(event, VehiclePosition):
            add_sample(self.timeline.positions, event.t, (event.x, event.y, event.z))
        elif _plotted_position(event):
            assert isinstance(event, TrajectorySetpoint | SetPositionTargetLocal)
            add_sample(self.timeline.setpoint_positions, event.t, event.position)

    def finish(self, t_end: float) -> list[Finding]:
        self._flush()
        self._transitions(self.gate.finish(t_end))
        for check in self.checks:
            check.finish(t_end)
        if self.timeline is not None:
            self.timeline.loss_timeout = self.gate.loss_timeout
            self.timeline.recorded_params = dict(self.gate.recorded_params)
        return self.ctx.findings


NOTED = (StatusText, Command, CommandAck)


def _plotted_position(event: Event) -> bool:
    """A trajectory setpoint, or a MAVLink one in MAV_FRAME_LOCAL_NED (1) whose type mask does
    not ignore the position (other frames are not in the vehicle's local frame)."""
    if isinstance(event, TrajectorySetpoint):
        return True
    return (
        isinstance(event, SetPositionTargetLocal)
        and event.coordinate_frame == 1
        and not event.type_mask & POSITION_BITS
    )


def run_events(
    events: Iterable[Event],
    info: RecordingInfo,
    profile: Profile,
    settings: Settings,
    *,
    timelines: dict[str, Timeline] | None = None,
    on_event: Callable[[int], None] | None = None,
    batching: bool = True,
    end_t: Callable[[], float | None] | None = None,
) -> tuple[list[Finding], RunStats]:
    """Run the gate and every enabled check over ``events`` (one recording, any vehicles).

    ``batching=False`` hands every stream message to every check one at a time, as the
    checks' ``on_batch`` must be equivalent to (the tests compare the two). ``end_t`` gives,
    once the events are used up, the time of the recording's last message when it is later
    than its last event (``recording.Aside``): the recording ends there."""
    with _fewer_collections():
        return _run_events(events, info, profile, settings, timelines, on_event, batching, end_t)


@contextmanager
def _fewer_collections() -> Iterator[None]:
    """Collect the youngest generation less often for the pass (``YOUNG_COLLECTION_EVERY``);
    the caller's thresholds are back afterwards, also for a library user's process."""
    before = gc.get_threshold()
    if before[0]:  # 0: the caller switched automatic collection off
        gc.set_threshold(max(before[0], YOUNG_COLLECTION_EVERY), *before[1:])
    try:
        yield
    finally:
        gc.set_threshold(*before)


def _run_events(
    events: Iterable[Event],
    info: RecordingInfo,
    profile: Profile,
    settings: Settings,
    timelines: dict[str, Timeline] | None,
    on_event: Callable[[int], None] | None,
    batching: bool,
    end_t: Callable[[], float | None] | None,
) -> tuple[list[Finding], RunStats]:
    runs: dict[str, VehicleRun] = {}
    kinds: Counter[str] = Counter()
    count = 0
    t_end = 0.0
    for event in events:
        run = runs.get(event.vehicle)
        if run is None:
            timeline = None
            if timelines is not None:
                timeline = timelines.setdefault(event.vehicle, Timeline())
            run = runs[event.vehicle] = VehicleRun(
                event.vehicle, profile, settings, info, timeline, batching=batching
            )
        run.feed(event)
        kinds[event.kind] += 1
        if event.t > t_end:  # max(t_end, event.t) without the call
            t_end = event.t
        count += 1
        if on_event is not None and count % 4096 == 0:
            on_event(count)
    last_message = end_t() if end_t is not None else None
    if last_message is not None and last_message > t_end:
        t_end = last_message
    findings: list[Finding] = []
    for run in runs.values():
        findings.extend(run.finish(t_end))
    contexts = [run.ctx for run in runs.values()]
    unseen = sorted(v for v, run in runs.items() if run.offboard_seen)
    if unseen and settings.enabled("OFB002"):
        flag = any(runs[v].gate.follows_flag for v in unseen)
        findings.append(_stream_not_recorded(unseen, info, settings, flag))
    if not runs:
        # No event at all: every rule that needs a stream is not checkable.
        empty = VehicleRun("", profile, settings, info, None)
        findings.extend(empty.finish(0.0))
        contexts.append(empty.ctx)
    findings.extend(recording_findings(contexts, settings))
    stats: RunStats = {
        "events": count,
        "duration_s": round(t_end, 6),
        "vehicles": sorted(runs),
        "kinds": dict(sorted(kinds.items())),
    }
    return findings, stats


def _stream_not_recorded(
    vehicles: list[str], info: RecordingInfo, settings: Settings, follows_flag: bool
) -> Finding:
    """The one OFB002 of a recording without the sent stream that shows offboard in use."""
    codes = ", ".join(c for c in sent_stream_rules() if settings.enabled(c))
    who = f" on vehicle {', '.join(vehicles)}" if any(vehicles) else ""
    missing = info.stream_missing or "does not hold the stream sent to the vehicle"
    if follows_flag:
        signal = (
            "the gate model takes PX4's own recorded verdict "
            "(failsafe_flags.offboard_control_signal_lost) as the offboard signal"
        )
    else:
        signal = (
            "the gate model takes the offboard signal as present and counts a loss only "
            "where PX4's own failsafe is recorded"
        )
    return Finding(
        code="OFB002",
        name=get_rule("OFB002").name,
        severity=settings.severity_of("OFB002", Severity.INFO),
        message=(
            f"the recording shows offboard in use{who} but {missing}. The stream "
            f"rules ({codes}) cannot be checked here: they need the companion's side of the "
            "link (a tlog recorded on the companion or by a router forwarding its messages, "
            "the /fmu/in topics, or a ULog with offboard_control_mode). Modes, acks and PX4's "
            f"failsafe messages are still checked: {signal}. If this is the companion's own "
            "log, it sent no setpoint at all"
        ),
        summary="no companion stream in the recording (a ground station's log?): stream rules "
        "not checked",
        vehicle=vehicles[0] if len(vehicles) == 1 else "",
    )


def _takes_runs(check: Check) -> bool:
    """Does the check want any stream message (then it takes them as runs)?"""
    return any(issubclass(cls, check.subscriptions) for cls in STREAM_TYPES)


def _sort_key(finding: Finding) -> tuple[float, str, str]:
    """In time order, whole-file findings first; but what could not be checked (OFB002) last,
    after what was found."""
    if finding.code == "OFB002":
        return (math.inf, finding.vehicle, finding.code)
    t = -math.inf if finding.time_s is None else finding.time_s
    return (t, finding.vehicle, finding.code)


def lint_file(
    path: str | Path,
    settings: Settings | None = None,
    *,
    progress: Progress | None = None,
    timelines: dict[str, Timeline] | None = None,
    batching: bool = True,
    plot_data: bool = False,
) -> FileReport:
    """Lint one recording. Never raises for a bad file: it becomes OFB001 and ``complete=False``.

    ``batching=False`` gives every check the stream one message at a time (see ``run_events``);
    ``plot_data`` has the reader hand what only the HTML report's plots show (the positions it
    thins out of the events) to ``timelines``, beside the events: the findings are the same."""
    settings = (settings or Settings()).for_recording(path)
    path = Path(path)
    name = path_text(path)
    unreadable = get_rule("OFB001")
    try:
        source = open_source(path)
        source.px4_hint = settings.release
        plot = source.aside.plot = PlotSamples() if plot_data else None

        def show() -> None:
            fraction = source.progress() if progress is not None else None
            if progress is not None and fraction is not None:
                progress(fraction)

        source.on_progress = show if progress is not None else None
        source.open()
    except SourceError as exc:
        report = FileReport(name, "unknown", resolve_profile(RecordingInfo(name, "?"), settings))
        report.complete = False
        report.problems.append(exc.line())
        report.findings.append(
            Finding(
                "OFB001",
                unreadable.name,
                Severity.ERROR,
                exc.line(),
                where=_place(exc),
                summary=_unreadable(exc),
            )
        )
        return report
    try:
        try:
            info = source.probe()
        except SourceError as exc:
            info = RecordingInfo(name, source.format)
            source.problems.append(_problem(exc))
        profile = resolve_profile(info, settings)
        report = FileReport(name, source.format, profile)

        def tick(_: int) -> None:
            show()

        findings, stats = run_events(
            _until_unreadable(source.events(), source.problems),
            info,
            profile,
            settings,
            timelines=timelines,
            on_event=tick,
            batching=batching,
            end_t=lambda: source.aside.end_t,
        )
    finally:
        source.close()
    if plot is not None and timelines is not None:
        _add_plotted(timelines, plot)
    malformed = get_rule("OFB004")
    for problem in source.problems:
        line = problem.line(name)
        if problem.lost:
            report.problems.append(line)
            findings.append(
                Finding(
                    "OFB001",
                    unreadable.name,
                    Severity.ERROR,
                    line,
                    time_s=problem.time_s,
                    where=_place(problem),
                    summary=_unreadable(problem),
                )
            )
        else:
            report.malformed.append(line)
            findings.append(
                Finding(
                    "OFB004",
                    malformed.name,
                    settings.severity_of("OFB004", Severity.INFO),
                    line,
                    time_s=problem.time_s,
                    where=_place(problem),
                    summary=_unreadable(problem),
                )
            )
    report.complete = not report.problems
    if not report.complete:
        findings = [in_readable_part(f) for f in findings]
    vehicle_assumed = info.vehicle_assumed if settings.vehicle is None else None
    if settings.enabled("OFB003") and (
        not (profile.px4_detected and profile.vehicle_detected) or vehicle_assumed
    ):
        findings.append(_assumed(profile, vehicle_assumed, info.px4_candidates))
    findings = [f for f in findings if settings.enabled(f.code)]
    findings.sort(key=_sort_key)
    report.findings = findings
    # the run's keys and the reader's are disjoint (mypy cannot merge TypedDicts by **)
    report.stats = cast(FileStats, {**stats, **source.stats})
    if source.start_time_s is not None:
        report.stats["start_unix_s"] = round(source.start_time_s, 6)
    if info.notes:
        report.stats["notes"] = info.notes
    if progress is not None:
        progress(1.0)
    return report


def _add_plotted(timelines: dict[str, Timeline], plot: PlotSamples) -> None:
    """The positions the reader thinned out of the events, in the timelines beside the ones
    judged (in time order, one per ``SAMPLE_S`` at most, as if all had been events)."""
    for vehicle, samples in plot.positions.items():
        timeline = timelines.setdefault(vehicle, Timeline())
        merged: list[tuple[float, float, float, float]] = []
        for t, *xyz in sorted(timeline.positions + samples, key=lambda sample: sample[0]):
            add_sample(merged, t, (xyz[0], xyz[1], xyz[2]))
        timeline.positions = merged


def _until_unreadable(events: Iterable[Event], problems: list[SourceProblem]) -> Iterator[Event]:
    """The reader's events until it gives up: its error becomes a problem of the file and the
    run ends there normally, so the findings on what was read are kept."""
    try:
        yield from events
    except SourceError as exc:
        problems.append(_problem(exc))


def _unreadable(problem: SourceError | SourceProblem) -> str:
    """The problem without the file's name (the report's heading names the file)."""
    at = f" at {problem.where}" if problem.where else ""
    return clip(f"{problem.what}{at}")


def _place(problem: SourceError | SourceProblem) -> Where | None:
    """The byte of the file a problem's line names, as a finding's place (no topic)."""
    offset = first_byte(problem.where)
    return None if offset is None else Where("", offset=offset)


def _problem(exc: SourceError) -> SourceProblem:
    return SourceProblem(exc.what, exc.where)


def _assumed(
    profile: Profile, vehicle_assumed: str | None = None, candidates: Sequence[str] = ()
) -> Finding:
    missing = []
    if not profile.px4_detected and candidates:
        fits = " or ".join(candidates)
        missing.append(
            f"PX4 version: its message definitions and topic names fit {fits} "
            f"(assumed {profile.px4}; set --px4)"
        )
    elif not profile.px4_detected:
        missing.append(f"PX4 version (assumed {profile.px4}; set --px4)")
    if not profile.vehicle_detected:
        missing.append(f"vehicle type (assumed {profile.vehicle}; set --vehicle)")
    elif vehicle_assumed:
        missing.append(f"vehicle type fully: it says {vehicle_assumed}")
    guessed, options = [], []
    if not profile.px4_detected:
        guessed.append(f"PX4 {profile.px4}")
        options.append("--px4")
    if not profile.vehicle_detected or vehicle_assumed:
        guessed.append(profile.vehicle)
        options.append("--vehicle")
    rule = get_rule("OFB003")
    return Finding(
        "OFB003",
        rule.name,
        Severity.INFO,
        "the recording does not say its " + " or its ".join(missing),
        summary=f"profile assumed: {', '.join(guessed)} (set {' and '.join(options)})",
    )


class Lint(Protocol):
    """Lints one recording with the settings it is judged with (``lint_file``,
    ``lint_file_with_timelines``); a module-level function, so that workers can be sent it."""

    def __call__(
        self, path: str, settings: Settings, *, progress: Progress | None = None
    ) -> FileReport: ...


Watch = Callable[[str], AbstractContextManager[Progress | None]]
"""Shows one recording's progress while it is linted (a progress bar's task)."""


def plan_lint(
    paths: Sequence[str | Path], settings: Settings | None = None
) -> list[tuple[str, Settings]]:
    """The recordings under ``paths`` (files, bag folders and folders, searched once), each
    with the settings it is judged with (``Settings.resolved_for``): what ``lint_each`` takes."""
    settings = settings or Settings()
    return [(str(f), settings.resolved_for(f)) for f in recordings_in(paths)]


def _lint_one(args: tuple[Lint, str, Settings]) -> FileReport:
    lint, path, settings = args
    return lint(path, settings)


def lint_each(
    plan: Sequence[tuple[str, Settings]],
    *,
    lint: Lint = lint_file,
    jobs: int = 1,
    on_file: Callable[[FileReport], None] | None = None,
    watch: Watch | None = None,
) -> Report:
    """Lint each recording of ``plan`` (``plan_lint``) with its settings, in order: in this
    process, where ``watch`` may show each one's progress, or in ``jobs`` worker processes.
    The one way a local lint runs (``lint_paths``, ``fuzzoff lint``; a fleet's lint runs
    the same plan on Dask, ``fleet.lint_run``)."""
    report = Report()

    def done(file_report: FileReport) -> None:
        report.files.append(file_report)
        if on_file is not None:
            on_file(file_report)

    if jobs > 1 and len(plan) > 1:
        # imported here: a one-process lint need not pay for it at start-up
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(max_workers=jobs) as pool:
            for file_report in pool.map(_lint_one, [(lint, f, s) for f, s in plan]):
                done(file_report)
    elif watch is None:
        for f, s in plan:
            done(lint(f, s))
    else:
        for f, s in plan:
            with watch(f) as progress:
                done(lint(f, s, progress=progress))
    return report


def lint_paths(
    paths: Sequence[str | Path],
    settings: Settings | None = None,
    *,
    jobs: int = 1,
    on_file: Callable[[FileReport], None] | None = None,
    lint: Lint = lint_file,
) -> Report:
    """Lint files and folders (searched recursively). ``jobs`` > 1 uses worker processes."""
    return lint_each(plan_lint(paths, settings), lint=lint, jobs=jobs, on_file=on_file)


def timeline_loss_timeout(
    timeline: Timeline, profile: Profile, settings: Settings
) -> tuple[float, str]:
    """COM_OF_LOSS_T as the gate used it, and where the value came from.

    An engine that copies the gate's final ``loss_timeout`` and ``recorded_params`` onto the
    timeline gives the recording's own value; without them the value is ``--param`` /
    configuration, else the profile's default (what the gate model starts from). Before 1.11
    the timeout is a fixed 500 ms whatever COM_OF_LOSS_T says (gate.md#signal).
    """
    recorded = timeline.recorded_params
    value = timeline.loss_timeout
    if value is None:
        value = GateModel(profile, settings.params).loss_timeout
    if profile.release.fixed_loss_s is not None:
        return float(value), "fixed in PX4 before 1.11"  # COM_OF_LOSS_T is not the timeout
    if "COM_OF_LOSS_T" in settings.params:
        return float(value), settings.param_origin("COM_OF_LOSS_T")
    if "COM_OF_LOSS_T" in recorded:
        return float(value), "from the recording"
    return float(value), f"PX4 {profile.px4} default"


def lint_file_with_timelines(
    path: str | Path, settings: Settings, *, progress: Progress | None = None
) -> FileReport:
    """``lint_file`` with what the HTML report plots: every vehicle's timeline (every recorded
    position, not one per ``POSITION_PERIOD_S``) and the loss timeout the gate used."""
    settings = settings.for_recording(path)
    timelines: dict[str, Timeline] = {}
    report = lint_file(path, settings, progress=progress, timelines=timelines, plot_data=True)
    report.timelines = timelines
    report.loss_timeouts = {
        vehicle: timeline_loss_timeout(tl, report.profile, settings)
        for vehicle, tl in timelines.items()
    }
    return report
