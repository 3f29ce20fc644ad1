"""One vehicle's timeline as the data the HTML report's plots draw (``timeline.js``, uPlot).

Python decides what is shown and bounds its size; the page only draws. Per vehicle: the
keep-alive interval (a min and a max per bucket, with the age of the newest keep-alive rising
through every gap), the 2 Hz and loss-timeout lines, bands for the modelled signal, the recorded
and the predicted mode and each setpoint kind, the vehicle's position beside the position
setpoints, PX4's text messages, the commands and their acks, and one marker per finding. Text
from a recording travels as JSON data and is put on the page as text, never as markup.
"""

from __future__ import annotations

import itertools
import json
import math
import re
from collections.abc import Iterable, Sequence
from typing import Any

from fuzzoff.events import (
    MAV_CMD_COMPONENT_ARM_DISARM,
    MAV_CMD_DO_SET_MODE,
    VEHICLE_CMD_SET_NAV_STATE,
    Command,
    CommandAck,
    Event,
    StatusText,
)
from fuzzoff.findings import Finding
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import NAV_STATE_NAMES, custom_mode_to_nav_state, nav_state_name
from fuzzoff.profiles import Profile
from fuzzoff.report.sanitize import printable, show_bidi
from fuzzoff.timeline import Timeline

BUCKETS = 2000
"""Keep-alive intervals are reduced to a min and a max per bucket: at most 4,000 points, enough
to zoom in tenfold on a wide screen before two points share a pixel."""
MAX_SAMPLES = 4000
"""Longest position series sent to the page (evenly thinned beyond)."""
MAX_NOTES = 2000
"""Most text messages, commands and acks sent per vehicle."""
TEXT_LIMIT = 300
"""Longest text from a recording kept for one note."""

KEEPALIVE_RATE_S = 0.5
"""The 2 Hz minimum rate of the offboard docs (rules.md OFB101)."""
LEGACY_LOSS_S = 0.5
"""PX4 before 1.11 loses the signal after a fixed 500 ms (gate.md#signal)."""

RAMP_STEPS = 16
RAMP_MIN_S = 0.1
"""Intervals shorter than this are drawn as they are (the ramp would be invisible)."""

SEVERITY_CLASS = {0: "info", 1: "warning", 2: "error"}

MAV_SEVERITY_CLASS = {0: "error", 1: "error", 2: "error", 3: "error", 4: "warning"}
"""MAV_SEVERITY EMERGENCY..ERROR are errors, WARNING a warning, the rest information."""

COMMAND_NAMES = {
    20: "return",
    21: "land",
    22: "takeoff",
    176: "set mode",
    300: "mission start",
    400: "arm/disarm",
    511: "set message interval",
    512: "request message",
    519: "request protocol version",
    401: "run prearm checks",
    VEHICLE_CMD_SET_NAV_STATE: "set nav state",
}
"""The commands an offboard program sends most, by id (MAV_CMD; 100001 is PX4's own)."""

HOUSEKEEPING = frozenset({511, 512, 519, 520, 1000, 1001})
"""Commands a ground station or PX4 itself sends to set up the link or a gimbal (message
intervals and requests, capabilities, gimbal manager): left off the timeline with their acks."""

_SGR = re.compile(r"\x1b\[[0-9;]*m")
"""Terminal colour codes, which PX4 puts in some logged messages (``\x1b[32mReady``)."""


@dataclass(frozen=True, slots=True)
class Marker:
    """A finding placed on the plot: ``ident`` links the marker and the table row."""

    ident: str
    finding: Finding


@dataclass(frozen=True, slots=True)
class Segment:
    start: float
    end: float
    label: str
    css: str


@dataclass(frozen=True, slots=True)
class LossLine:
    """What the plot says about the loss timeout: the line (None when it cannot be drawn) and
    the caption's words for it."""

    seconds: float | None
    label: str
    caption: str


def loss_line(seconds: float, source: str, profile: Profile, recorded: float | None) -> LossLine:
    """The loss-timeout line and its words, as the version's code means COM_OF_LOSS_T.

    Before 1.11 the loss comes after a fixed 500 ms and COM_OF_LOSS_T is an extra wait before
    the loss action (gate.md#signal). From 1.11 it is the timeout itself, and 0 means the signal
    counts as lost at once: nothing to draw on a log axis, and in a recording that names no
    release (the profile assumed) it usually means an older firmware, where 0 was the default.
    """
    if profile.release.fixed_loss_s is not None:
        extra = f"; COM_OF_LOSS_T {recorded:g} s more before the loss action" if recorded else ""
        return LossLine(
            LEGACY_LOSS_S,
            "loss after 500 ms (fixed before PX4 1.11)",
            f"the offboard signal is lost 500 ms after the newest keep-alive (fixed in PX4 "
            f"before 1.11){extra}",
        )
    if seconds <= 0:
        caption = (
            f"COM_OF_LOSS_T = 0 s ({source}): PX4 {profile.px4} would count the offboard "
            "signal as lost at once"
        )
        if profile.px4_source == "default" and source == "from the recording":
            caption += (
                "; the recording names no PX4 release and before 1.11 this parameter was an "
                "extra wait after a fixed 500 ms, 0 by default: if it is such a firmware, "
                "judge it with --px4 legacy"
            )
        return LossLine(None, "", caption)
    return LossLine(
        seconds,
        f"loss timeout (COM_OF_LOSS_T) {seconds:g} s",
        f"the loss timeout COM_OF_LOSS_T = {seconds:g} s ({source})",
    )


def min_max_buckets(
    times: Sequence[float], values: Sequence[float], t_end: float, buckets: int = BUCKETS
) -> list[tuple[float, float]]:
    """Downsample a series to at most two points per bucket (its min and max, in time order).

    Min/max keeps every spike visible, which is what matters for keep-alive gaps.
    """
    if len(times) <= 2 * buckets:
        return list(zip(times, values, strict=True))
    width = max(t_end, 1e-9) / buckets
    out: list[tuple[float, float]] = []
    current = -1
    lo: tuple[float, float] | None = None
    hi: tuple[float, float] | None = None

    def flush() -> None:
        if lo is not None and hi is not None:
            out.extend(sorted({lo, hi}))

    for t, v in zip(times, values, strict=True):
        bucket = min(int(t / width), buckets - 1)
        if bucket != current:
            flush()
            current, lo, hi = bucket, (t, v), (t, v)
            continue
        assert lo is not None and hi is not None
        if v < lo[1]:
            lo = (t, v)
        if v > hi[1]:
            hi = (t, v)
    flush()
    return out


def ramp(
    t_from: float, age_from: float, age_to: float, steps: int = RAMP_STEPS
) -> list[tuple[float, float]]:
    """The age of the newest keep-alive growing from ``age_from`` to ``age_to`` after ``t_from``.

    Sampled geometrically so that, on the log axis, the curve crosses the 500 ms and loss-timeout
    lines at the right time (a straight segment between two samples would cross them late).
    """
    if age_to <= age_from:
        return [(t_from + age_to, age_to)]
    ratio = (age_to / age_from) ** (1 / steps)
    return [(t_from + age_from * ratio**k, age_from * ratio**k) for k in range(steps + 1)]


def with_ramps(
    points: list[tuple[float, float]], floor: float, buckets_per_s: float = math.inf
) -> list[tuple[float, float]]:
    """Insert the growing age before every interval much longer than the one before it.

    A ramp gets a point per two buckets it spans (at most 16), so ramps add at most half the
    bucket count in points however many gaps there are.
    """
    out: list[tuple[float, float]] = []
    previous = floor
    for t, interval in points:
        if interval > 1.5 * previous and interval > RAMP_MIN_S:
            steps = int(max(1.0, min(RAMP_STEPS, interval * buckets_per_s / 2)))
            out.extend(ramp(t - interval, max(previous, floor), interval, steps)[:-1])
        out.append((t, interval))
        previous = max(interval, floor)
    return out


def mode_css(nav_state: int | None) -> str:
    if nav_state is None:
        return "m-unknown"
    if nav_state == 14:
        return "m-offboard"
    return f"m-{nav_state % 6}"


def steps_to_segments(steps: Iterable[tuple[float, str, str]], t_end: float) -> list[Segment]:
    """``(t, label, css)`` changes -> segments lasting until the next change or ``t_end``."""
    items = sorted(steps, key=lambda s: s[0])
    segments: list[Segment] = []
    for i, (t, label, css) in enumerate(items):
        end = max(items[i + 1][0] if i + 1 < len(items) else t_end, t)
        if end == t and i + 1 < len(items):
            continue  # replaced at the same instant
        last = segments[-1] if segments else None
        if last is not None and (last.label, last.css) == (label, css):
            segments[-1] = Segment(last.start, end, label, css)  # no change: one segment
        else:
            segments.append(Segment(t, end, label, css))
    return segments


def recorded_mode_segments(tl: Timeline, t_end: float) -> list[Segment]:
    steps = []
    for t, nav_state, armed in tl.recorded_modes:
        label = nav_state_name(nav_state)
        if armed is False:
            label += " (disarmed)"
        css = mode_css(nav_state) + (" disarmed" if armed is False else "")
        steps.append((t, label, css))
    return steps_to_segments(steps, t_end)


def predicted_mode_segments(tl: Timeline, t_end: float) -> list[Segment]:
    """The model starts from the first recorded mode (as GateModel does), then its transitions."""
    steps: list[tuple[float, str, str]] = []
    if tl.recorded_modes:
        t, nav_state, _ = tl.recorded_modes[0]
        steps.append((t, nav_state_name(nav_state), mode_css(nav_state)))
    for tr in tl.transitions:
        if tr.nav_state is not None:
            steps.append((tr.t, nav_state_name(tr.nav_state), mode_css(tr.nav_state)))
        elif tr.what == "disarmed":
            steps.append((tr.t, "disarmed", "m-unknown disarmed"))
    return steps_to_segments(steps, t_end)


def signal_segments(tl: Timeline, t_end: float) -> list[Segment]:
    steps: list[tuple[float, str, str]] = []
    for tr in tl.transitions:
        if tr.what == "signal_available":
            steps.append((tr.t, "offboard signal available", "s-ok"))
        elif tr.what == "signal_lost":
            steps.append((tr.t, "offboard signal lost", "s-lost"))
    return steps_to_segments(steps, t_end)


def presence_segments(times: Sequence[float], merge_gap: float) -> list[Segment]:
    """Sample times -> bars where samples are closer than ``merge_gap`` (bounded by buckets)."""
    segments: list[Segment] = []
    start: float | None = None
    last = 0.0
    for t in times:
        if start is None:
            start = last = t
        elif t - last > merge_gap:
            segments.append(Segment(start, last, "", "sp"))
            start = last = t
        else:
            last = t
    if start is not None:
        segments.append(Segment(start, last, "", "sp"))
    return segments


def command_label(command: int, params: Sequence[float]) -> str:
    """A command as a user names it: ``mode OFFBOARD``, ``arm``, ``takeoff``, ``command 42``."""
    if command == MAV_CMD_DO_SET_MODE and math.isfinite(params[1]) and math.isfinite(params[2]):
        main, sub = int(params[1]) & 0xFF, int(params[2]) & 0xFF
        nav = custom_mode_to_nav_state((main << 16) | (sub << 24))
        return f"mode {nav_state_name(nav)}" if nav is not None else f"mode {main}.{sub}"
    if command == VEHICLE_CMD_SET_NAV_STATE and math.isfinite(params[0]):
        return f"mode {NAV_STATE_NAMES.get(int(params[0]), int(params[0]))}"
    if command == MAV_CMD_COMPONENT_ARM_DISARM:
        word = {1: "arm", 0: "disarm"}.get(round(params[0]) if math.isfinite(params[0]) else -1)
        force = " (forced)" if math.isfinite(params[1]) and round(params[1]) == 21196 else ""
        return f"{word or 'arm/disarm'}{force}"
    return COMMAND_NAMES.get(command, f"command {command}")


ACK_WINDOW_S = 3.0
"""An ack this soon after a command of the same id answers it (drawn as one item)."""


def notes_of(events: Sequence[Event]) -> list[list[Any]]:
    """``[t, kind, level, label, text]`` per text message and per command, the command's ack
    folded into it (``mode OFFBOARD ✓``); an ack with no command before it stands alone."""
    notes: list[list[Any]] = []
    open_commands: dict[int, tuple[float, list[Any]]] = {}
    for event in events:
        t = round(event.t, 4)
        if isinstance(event, Command | CommandAck) and event.command in HOUSEKEEPING:
            continue
        if isinstance(event, StatusText):
            text = printable(_SGR.sub("", event.text).strip(), TEXT_LIMIT)
            level = MAV_SEVERITY_CLASS.get(event.severity, "info")
            kind = "failsafe" if "failsafe" in text.lower() else "msg"
            notes.append([t, kind, level, text[:48], f"{text} (MAV_SEVERITY {event.severity})"])
        elif isinstance(event, Command):
            label = command_label(event.command, event.params)
            note: list[Any] = [t, "cmd", "info", label, f"{label} (command {event.command})"]
            note[4] += ", no ack recorded"
            notes.append(note)
            open_commands[event.command] = (event.t, note)
        elif isinstance(event, CommandAck):
            word = "accepted" if event.accepted else event.result_name.lower().replace("_", " ")
            level = "ok" if event.accepted else "error"
            sent = open_commands.get(event.command)
            if sent is not None and event.t - sent[0] <= ACK_WINDOW_S:
                note = sent[1]
                if str(note[4]).endswith("no ack recorded"):
                    note[2] = level
                    note[3] += " ✓" if event.accepted else f" ✗ {word}"
                    note[4] = note[4].replace("no ack recorded", f"ack: {word} at {t:.3f} s")
                else:  # PX4 1.16 and 1.17 ack a mode switch twice
                    note[4] += f"; ack again: {word} at {t:.3f} s"
                continue
            name = COMMAND_NAMES.get(event.command, f"command {event.command}")
            notes.append([t, "ack", level, f"{name}: {word}", f"ack of {name}: {word}"])
    return notes


def _thin(samples: Sequence[tuple[float, ...]], limit: int = MAX_SAMPLES) -> list[list[Any]]:
    """Columns ``[t, altitude, x, y]`` (altitude = -z, NED), at most ``limit`` rows."""
    step = max(1, math.ceil(len(samples) / limit))
    rows = samples[::step]

    def r(v: float) -> float | None:
        return round(v, 3) if math.isfinite(v) else None

    return [
        [round(s[0], 4) for s in rows],
        [r(-s[3]) for s in rows],
        [r(s[1]) for s in rows],
        [r(s[2]) for s in rows],
    ]


def _y_range(intervals: Sequence[float], lines: Sequence[float]) -> tuple[float, float]:
    positive = [v for v in intervals if v > 0]
    lo_val = min(positive, default=0.01)
    hi_val = max([*positive, *lines], default=1.0)
    lo = 10 ** math.floor(math.log10(max(lo_val, 1e-4)))
    hi = 10 ** math.ceil(math.log10(hi_val * 1.2))
    return lo, max(hi, lo * 10)


def _keepalive(tl: Timeline, t_end: float, loss: LossLine) -> dict[str, Any]:
    times = tl.keepalive
    intervals = [b - a for a, b in itertools.pairwise(times)]
    tail = t_end - times[-1] if times else 0.0
    lines = [KEEPALIVE_RATE_S] + ([loss.seconds] if loss.seconds else [])
    lo, hi = _y_range([*intervals, tail], lines)
    points = with_ramps(
        min_max_buckets(times[1:], intervals, t_end), lo, BUCKETS / max(t_end, 1e-3)
    )
    out: dict[str, Any] = {
        "t": [round(t, 4) for t, _ in points],
        "v": [round(max(v, lo), 5) for _, v in points],
        "y": [lo, hi],
        "lines": [[KEEPALIVE_RATE_S, "500 ms (2 Hz)", "rate"]],
        "tail": None,
    }
    if loss.seconds is not None:
        if math.isclose(loss.seconds, KEEPALIVE_RATE_S):
            out["lines"] = [[loss.seconds, f"500 ms: 2 Hz and {loss.label}", "loss"]]
        else:
            out["lines"].append([loss.seconds, loss.label, "loss"])
    if times and tail > KEEPALIVE_RATE_S:
        start = points[-1][1] if points else lo
        rise = ramp(times[-1], max(start, lo), tail)
        out["tail"] = [[round(t, 4) for t, _ in rise], [round(v, 5) for _, v in rise]]
    return out


def vehicle_plot(
    tl: Timeline, markers: Sequence[Marker], *, t_end: float, loss: LossLine, name: str
) -> dict[str, Any]:
    """Everything the page draws for one vehicle, as JSON-ready values."""
    t_end = max(
        [t_end, *tl.keepalive[-1:], *(m.finding.end_s or 0.0 for m in markers)], default=t_end
    )
    merge_gap = max(KEEPALIVE_RATE_S, 2 * t_end / BUCKETS)
    bands = [
        ("signal (model)", signal_segments(tl, t_end), "no signal transitions"),
        ("recorded mode", recorded_mode_segments(tl, t_end), "mode not recorded"),
        ("predicted mode", predicted_mode_segments(tl, t_end), "no prediction"),
    ]
    for kind, times in sorted(tl.setpoint_kinds.items()):
        bands.append((kind, presence_segments(times, merge_gap), "none"))
    if not tl.setpoint_kinds:
        bands.append(("setpoints sent", [], "no setpoints recorded"))
    notes = notes_of(tl.notes[:MAX_NOTES])
    marks = []
    for m in markers:
        f = m.finding
        if f.time_s is None:
            continue
        end = round(f.end_s, 4) if f.end_s is not None and f.end_s > f.time_s else None
        sev = SEVERITY_CLASS.get(int(f.severity), "info")
        title = f"{f.code} {sev} at {f.time_s:.3f} s: {printable(f.message, TEXT_LIMIT)}"
        marks.append([round(f.time_s, 4), end, sev, f.code, m.ident, title])
    return {
        "name": name,
        "end": round(t_end, 4),
        "keepalive": _keepalive(tl, t_end, loss) if tl.keepalive else None,
        "bands": [
            {
                "name": band,
                "empty": empty,
                "segs": [[round(s.start, 4), round(s.end, 4), s.label, s.css] for s in segs],
            }
            for band, segs, empty in bands
        ],
        "position": _thin(tl.positions) if tl.positions else None,
        "setpoint": _thin(tl.setpoint_positions) if tl.setpoint_positions else None,
        "notes": notes,
        "more_notes": max(0, len(tl.notes) - MAX_NOTES),
        "marks": marks,
    }


def as_script_data(value: Any) -> str:
    """JSON for a ``<script type="application/json">`` element: ``<``, ``>`` and ``&`` written
    as escapes, so no text from a recording can close the element or open a comment; NaN and
    infinity (not JSON) become null; bidi controls in its strings are shown as ``\\uNNNN``, as
    everywhere else in the report (they would reorder the labels the script draws)."""
    text = json.dumps(_finite(value), ensure_ascii=False, separators=(",", ":"))
    return (
        text.replace("<", "\\u003c")
        .replace(">", "\\u003e")
        .replace("&", "\\u0026")
        .replace("\u2028", "\\u2028")
        .replace("\u2029", "\\u2029")
    )


def _finite(value: Any) -> Any:
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, str):
        return show_bidi(value)
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value
