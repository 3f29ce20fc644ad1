"""One vehicle's timeline as inline SVG, written by hand (no plotting library).

The plot is a few lines, rectangles and links: a log-scale keep-alive interval panel with the
2 Hz (500 ms) and loss-timeout lines, bands for the modelled offboard signal, the recorded mode and
the gate-predicted mode, one band per setpoint kind, and one marker per finding that links to its
row in the findings table (``#finding-ID``) and is itself the target ``#mark-ID``. Every text that
may come from a recording is escaped; the number of drawn points is bounded by the plot width.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from html import escape

from fuzzoff.engine import Timeline
from fuzzoff.events import NAV_STATE_OFFBOARD
from fuzzoff.findings import Finding
from fuzzoff.modes import nav_state_name
from fuzzoff.report.sanitize import printable

WIDTH = 1000
LEFT = 130
RIGHT = 16
TOP = 22
PANEL_H = 170
BAND_H = 16
BAND_GAP = 4
AXIS_H = 30
LABEL_CHARS = 20
CHAR_W = 6.5
"""Width of one character of a band label (10 px sans-serif), to leave out labels that overflow."""
MAX_BUCKETS = WIDTH - LEFT - RIGHT
"""Keep-alive intervals are reduced to a min and a max per pixel column (at most 2 per column)."""

KEEPALIVE_RATE_S = 0.5
"""The 2 Hz minimum rate of the offboard docs (rules.md OFB101)."""

RAMP_STEPS = 16
RAMP_MIN_S = 0.1
"""Intervals shorter than this are drawn as they are (the ramp would be invisible)."""

SEVERITY_CLASS = {0: "info", 1: "warning", 2: "error"}


@dataclass(frozen=True, slots=True)
class Segment:
    start: float
    end: float
    label: str
    css: str


@dataclass(frozen=True, slots=True)
class Marker:
    """A finding placed on the plot: ``ident`` links the marker and the table row."""

    ident: str
    finding: Finding


def attr(value: str) -> str:
    """Text for a double-quoted attribute or element content (control characters as \\xNN)."""
    return escape(printable(value, 4000), quote=True)


def fmt(value: float) -> str:
    return f"{value:.1f}"


class _Scale:
    def __init__(self, t_end: float) -> None:
        self.t_end = max(t_end, 1e-3)
        self.x0 = LEFT
        self.x1 = WIDTH - RIGHT

    def x(self, t: float) -> float:
        t = min(max(t, 0.0), self.t_end)
        return self.x0 + (self.x1 - self.x0) * t / self.t_end


def nice_step(span: float, target: int = 8) -> float:
    raw = span / max(target, 1)
    power = 10 ** math.floor(math.log10(raw)) if raw > 0 else 1.0
    for mult in (1, 2, 5, 10):
        if mult * power >= raw:
            return mult * power
    return 10 * power


def min_max_buckets(
    times: Sequence[float], values: Sequence[float], t_end: float, buckets: int = MAX_BUCKETS
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
    points: list[tuple[float, float]], floor: float, px_per_s: float = math.inf
) -> list[tuple[float, float]]:
    """Insert the growing age before every interval much longer than the one before it.

    A ramp gets a point per two pixels it spans (at most 16), so ramps add at most half the
    plot width in points however many gaps there are.
    """
    out: list[tuple[float, float]] = []
    previous = floor
    for t, interval in points:
        if interval > 1.5 * previous and interval > RAMP_MIN_S:
            steps = int(max(1.0, min(RAMP_STEPS, interval * px_per_s / 2)))
            out.extend(ramp(t - interval, max(previous, floor), interval, steps)[:-1])
        out.append((t, interval))
        previous = max(interval, floor)
    return out


def mode_css(nav_state: int | None) -> str:
    if nav_state is None:
        return "m-unknown"
    if nav_state == NAV_STATE_OFFBOARD:
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


def presence_segments(times: Sequence[float], t_end: float, merge_gap: float) -> list[Segment]:
    """Sample times -> bars where samples are closer than ``merge_gap`` (bounded by pixels)."""
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


def _band(y: float, label: str, segments: list[Segment], scale: _Scale, empty: str) -> list[str]:
    short = label if len(label) <= LABEL_CHARS else label[: LABEL_CHARS - 1] + "…"
    out = [
        f'<text class="lbl" x="{LEFT - 6}" y="{fmt(y + BAND_H - 4)}">{attr(short)}'
        f"<title>{attr(label)}</title></text>"
    ]
    out.append(
        f'<rect class="band-bg" x="{LEFT}" y="{fmt(y)}" width="{scale.x1 - scale.x0}" '
        f'height="{BAND_H}"/>'
    )
    if not segments:
        out.append(
            f'<text class="none" x="{LEFT + 4}" y="{fmt(y + BAND_H - 4)}">{attr(empty)}</text>'
        )
    for seg in segments:
        x = scale.x(seg.start)
        w = max(scale.x(seg.end) - x, 1.0)
        title = seg.label or label
        out.append(
            f'<rect class="{attr(seg.css)}" x="{fmt(x)}" y="{fmt(y)}" width="{fmt(w)}" '
            f'height="{BAND_H}"><title>{attr(title)} from {seg.start:.3f} s to {seg.end:.3f} s'
            f"</title></rect>"
        )
        if seg.label and w > CHAR_W * len(seg.label) + 6:
            out.append(
                f'<text class="seg" x="{fmt(x + 3)}" y="{fmt(y + BAND_H - 4)}">'
                f"{attr(seg.label)}</text>"
            )
    return out


def _y_range(intervals: Sequence[float], lines: Sequence[float]) -> tuple[float, float]:
    positive = [v for v in intervals if v > 0]
    lo_val = min(positive, default=0.01)
    hi_val = max([*positive, *lines], default=1.0)
    lo = 10 ** math.floor(math.log10(max(lo_val, 1e-4)))
    hi = 10 ** math.ceil(math.log10(hi_val * 1.2))
    return lo, max(hi, lo * 10)


def _keepalive_panel(tl: Timeline, scale: _Scale, loss_timeout: float, t_end: float) -> list[str]:
    top, bottom = TOP, TOP + PANEL_H
    times = tl.keepalive
    intervals = [b - a for a, b in itertools.pairwise(times)]
    tail = t_end - times[-1] if times else 0.0
    lines = [KEEPALIVE_RATE_S] + ([loss_timeout] if loss_timeout > 0 else [])
    lo, hi = _y_range([*intervals, tail], lines)

    def y(value: float) -> float:
        value = min(max(value, lo), hi)
        frac = (math.log10(value) - math.log10(lo)) / (math.log10(hi) - math.log10(lo))
        return bottom - frac * (bottom - top)

    out = [
        f'<rect class="panel" x="{LEFT}" y="{top}" width="{scale.x1 - scale.x0}" '
        f'height="{PANEL_H}"/>',
        f'<text class="lbl" x="{LEFT - 6}" y="{top - 8}">keep-alive interval</text>'
        f'<text class="none" x="{LEFT + 4}" y="{top + 12}">time since the previous '
        "keep-alive, at each message (log scale)</text>",
    ]
    decade = lo
    while decade <= hi * 1.0001:
        label = f"{decade * 1000:g} ms" if decade < 1 else f"{decade:g} s"
        out.append(
            f'<line class="grid" x1="{LEFT}" x2="{scale.x1}" y1="{fmt(y(decade))}" '
            f'y2="{fmt(y(decade))}"/><text class="tick" x="{LEFT - 6}" '
            f'y="{fmt(y(decade) + 4)}">{label}</text>'
        )
        decade *= 10
    if not times:
        out.append(
            f'<text class="none" x="{LEFT + 8}" y="{top + 20}">no keep-alive messages from '
            "this vehicle</text>"
        )
    px_per_s = (scale.x1 - scale.x0) / scale.t_end
    points = with_ramps(min_max_buckets(times[1:], intervals, t_end), lo, px_per_s)
    if points:
        path = " ".join(f"{fmt(scale.x(t))},{fmt(y(v))}" for t, v in points)
        out.append(
            f'<polyline class="series" points="{path}"><title>time since the previous '
            "keep-alive message</title></polyline>"
        )
    if times and tail > KEEPALIVE_RATE_S:
        start = points[-1][1] if points else lo
        path = " ".join(f"{fmt(scale.x(t))},{fmt(y(v))}" for t, v in ramp(times[-1], start, tail))
        out.append(
            f'<polyline class="tail" points="{path}"><title>no keep-alive for the last '
            f"{tail:.3f} s of the recording</title></polyline>"
        )
    out.append(
        f'<line class="rate" x1="{LEFT}" x2="{scale.x1}" y1="{fmt(y(KEEPALIVE_RATE_S))}" '
        f'y2="{fmt(y(KEEPALIVE_RATE_S))}"/><text class="rate-l" x="{scale.x1 - 4}" '
        f'y="{fmt(y(KEEPALIVE_RATE_S) + 12)}">500 ms (2 Hz)</text>'
    )
    if loss_timeout > 0:
        out.append(
            f'<line class="loss" x1="{LEFT}" x2="{scale.x1}" y1="{fmt(y(loss_timeout))}" '
            f'y2="{fmt(y(loss_timeout))}"/><text class="loss-l" x="{LEFT + 4}" '
            f'y="{fmt(y(loss_timeout) - 4)}">loss timeout (COM_OF_LOSS_T) {loss_timeout:g} s'
            "</text>"
        )
    return out


def _time_axis(y: float, scale: _Scale) -> list[str]:
    step = nice_step(scale.t_end)
    out = [f'<line class="axis" x1="{LEFT}" x2="{scale.x1}" y1="{fmt(y)}" y2="{fmt(y)}"/>']
    tick = 0.0
    while tick <= scale.t_end + 1e-9:
        x = scale.x(tick)
        out.append(
            f'<line class="axis" x1="{fmt(x)}" x2="{fmt(x)}" y1="{fmt(y)}" y2="{fmt(y + 4)}"/>'
            f'<text class="ttick" x="{fmt(x)}" y="{fmt(y + 16)}">{tick:g}</text>'
        )
        tick += step
    out.append(f'<text class="lbl" x="{scale.x1}" y="{fmt(y + 28)}">time (s)</text>')
    return out


def _markers(markers: Sequence[Marker], scale: _Scale, bottom: float) -> list[str]:
    out = []
    for marker in markers:
        f = marker.finding
        if f.time_s is None:
            continue
        x = scale.x(f.time_s)
        css = SEVERITY_CLASS.get(int(f.severity), "info")
        title = f"{f.code} at {f.time_s:.3f} s: {f.message}"
        parts = [
            f'<a class="mark {css}" id="mark-{attr(marker.ident)}" '
            f'href="#finding-{attr(marker.ident)}"><title>{attr(title)}</title>'
        ]
        if f.end_s is not None and f.end_s > f.time_s:
            w = max(scale.x(f.end_s) - x, 1.0)
            parts.append(
                f'<rect class="span" x="{fmt(x)}" y="{TOP}" width="{fmt(w)}" '
                f'height="{fmt(bottom - TOP)}"/>'
            )
        parts.append(
            f'<line x1="{fmt(x)}" x2="{fmt(x)}" y1="{TOP}" y2="{fmt(bottom)}"/>'
            f'<path d="M{fmt(x - 5)},{TOP - 10} L{fmt(x + 5)},{TOP - 10} L{fmt(x)},{TOP} Z"/></a>'
        )
        out.append("".join(parts))
    return out


def timeline_svg(
    tl: Timeline,
    markers: Sequence[Marker],
    *,
    t_end: float,
    loss_timeout: float,
    label: str,
) -> str:
    """The SVG element for one vehicle (``label`` names it for screen readers)."""
    t_end = max(
        [t_end, *tl.keepalive[-1:], *(m.finding.end_s or 0.0 for m in markers)], default=t_end
    )
    scale = _Scale(t_end)
    body = _keepalive_panel(tl, scale, loss_timeout, t_end)
    y = TOP + PANEL_H + 10
    bands: list[tuple[str, list[Segment], str]] = [
        ("signal (model)", signal_segments(tl, t_end), "no signal transitions"),
        ("recorded mode", recorded_mode_segments(tl, t_end), "mode not recorded"),
        ("predicted mode", predicted_mode_segments(tl, t_end), "no prediction"),
    ]
    merge_gap = max(KEEPALIVE_RATE_S, 2 * t_end / MAX_BUCKETS)
    for kind, times in sorted(tl.setpoint_kinds.items()):
        bands.append((kind, presence_segments(times, t_end, merge_gap), "none"))
    if not tl.setpoint_kinds:
        bands.append(("setpoints sent", [], "no setpoints recorded"))
    for name, segments, empty in bands:
        body.extend(_band(y, name, segments, scale, empty))
        y += BAND_H + BAND_GAP
    bottom = y - BAND_GAP
    body.extend(_time_axis(bottom + 4, scale))
    body.extend(_markers(markers, scale, bottom))
    height = bottom + AXIS_H + 8
    return (
        f'<svg class="timeline" xmlns="http://www.w3.org/2000/svg" role="img" '
        f'viewBox="0 0 {WIDTH} {fmt(height)}" width="{WIDTH}" height="{fmt(height)}" '
        f'aria-label="{attr(label)}"><title>{attr(label)}</title>' + "".join(body) + "</svg>"
    )
