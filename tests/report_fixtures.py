"""In-memory reports for the renderer tests, with hostile strings where a recording can put text."""

from __future__ import annotations

from pathlib import Path

from fuzzoff.config import Settings
from fuzzoff.engine import Timeline, timeline_loss_timeout
from fuzzoff.events import Event, SetPositionTargetLocal, StatusText, VehicleStatus, Where
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.formats.tlog.writer import write_tlog
from fuzzoff.gate import GateTransition
from fuzzoff.profiles import Profile

SCRIPT = "<script>document.title='pwned';console.error('pwned')</script>"
ONERROR = '" onerror="document.title=\'pwned\'" x="'
IMG = "<img src=x onerror=\"document.title='pwned';console.error('pwned')\">"
ANSI = "\x1b[2J\x1b[31m"
HOSTILE = f"{SCRIPT}{ONERROR}{IMG}{ANSI}"
VEHICLE = f"/px4_{SCRIPT}"
TOPIC = f"/fmu/in/offboard_control_mode{ONERROR}{SCRIPT}"


def hostile_timeline() -> Timeline:
    """20 s at 20 Hz with a 1.5 s gap at 8 s, a failsafe and a return to OFFBOARD."""
    keepalive = [i * 0.05 for i in range(161)] + [9.5 + i * 0.05 for i in range(211)]
    tl = Timeline(keepalive=keepalive)
    tl.recorded_modes = [(0.0, 2, True), (3.0, 14, True), (9.1, 2, True), (12.0, 14, True)]
    tr = [
        ("signal_available", 0.0, None),
        ("signal_lost", 9.0, None),
        ("failsafe", 9.0, 2),
        ("signal_available", 9.5, None),
        ("mode", 12.0, 14),
    ]
    tl.transitions = [
        GateTransition(t=t, vehicle=VEHICLE, what=what, message=HOSTILE, spec="2.1", nav_state=n)  # type: ignore[arg-type]
        for what, t, n in tr
    ]
    tl.setpoint_kinds = {
        "trajectory": [i * 0.1 for i in range(80)] + [9.5 + i * 0.1 for i in range(105)],
        f"kind{IMG}": [1.0, 1.1, 1.2, 15.0],
    }
    tl.notes = [StatusText(t=9.0, vehicle=VEHICLE, severity=2, text=f"failsafe {HOSTILE}")]
    return tl


def hostile_findings() -> list[Finding]:
    return [
        Finding("OFB003", "profile-assumed", Severity.INFO, f"assumed {HOSTILE}"),
        Finding(
            "OFB001",
            "unreadable-input",
            Severity.ERROR,
            f"message text {HOSTILE}",
            time_s=9.0,
            end_s=9.5,
            where=Where(TOPIC, index=180, offset=4242),
            vehicle=VEHICLE,
        ),
        Finding(
            "OFB002",
            "rule-not-checkable",
            Severity.INFO,
            f"OFB003 (x) cannot be checked on this recording: {HOSTILE}",
            time_s=12.0,
            where=Where(TOPIC),
            vehicle=VEHICLE,
        ),
    ]


def with_plots(file: FileReport, timelines: dict[str, Timeline]) -> None:
    """Give ``file`` these timelines to plot, with the loss timeout a lint would give them."""
    file.timelines = timelines
    file.loss_timeouts = {
        vehicle: timeline_loss_timeout(tl, file.profile, Settings())
        for vehicle, tl in timelines.items()
    }


def hostile_report() -> Report:
    """Two recordings: one with a timeline and three findings, one unreadable."""
    good = FileReport(
        path=f"corpora/demo/{SCRIPT}{ONERROR}.tlog",
        format="tlog",
        profile=Profile("1.15", "mc", px4_detected=True, px4_release=f"1.15.4{SCRIPT}"),
        findings=hostile_findings(),
        stats={"events": 1234, "duration_s": 20.0, "vehicles": [VEHICLE]},
    )
    with_plots(good, {VEHICLE: hostile_timeline()})
    bad = FileReport(
        path=f"broken{IMG}.ulg",
        format="unknown",
        profile=Profile(),
        complete=False,
        problems=[f"broken{IMG}.ulg: not a ULog file {HOSTILE}"],
        findings=[
            Finding("OFB001", "unreadable-input", Severity.ERROR, f"not a ULog file {HOSTILE}")
        ],
    )
    return Report(files=[good, bad])


def gap_recording(path: Path) -> Path:
    """A real tlog: 5 s of SET_POSITION_TARGET_LOCAL_NED at 20 Hz, armed in OFFBOARD from 0.5 s,
    with a 1.5 s gap from 2 s (long enough for the keep-alive and loss rules)."""
    events: list[Event] = []
    for i in range(100):
        t = i * 0.05
        if not 2.0 < t < 3.5:
            events.append(SetPositionTargetLocal(t=t, target_system=1, target_component=1))
        if i % 20 == 0:
            nav_state = 14 if t > 0.5 else 2
            events.append(
                VehicleStatus(t=t + 0.001, nav_state=nav_state, armed=True, origin="vehicle")
            )
    return write_tlog(path, events)
