"""The HTML report as a document: self-contained, escaped, bounded in size (browser tests apart)."""

from __future__ import annotations

import base64
import hashlib
import itertools
import json
import math
import re
from dataclasses import replace
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

from fuzzoff.catalog import REFERENCE_PREFIXES
from fuzzoff.config import Settings
from fuzzoff.engine import Timeline, lint_file, lint_file_with_timelines, timeline_loss_timeout
from fuzzoff.events import (
    Command,
    CommandAck,
    Event,
    SetPositionTargetLocal,
    StatusText,
    VehiclePosition,
    VehicleStatus,
)
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.formats.tlog.writer import write_tlog
from fuzzoff.profiles import Profile
from fuzzoff.report.html import render
from fuzzoff.report.html_plot import BUCKETS, as_script_data, min_max_buckets, with_ramps
from tests.helpers import CORPORA, ROOT, run_cli
from tests.report_fixtures import SCRIPT, gap_recording, hostile_report, with_plots


class Markup(HTMLParser):
    """Every tag and attribute as a browser's parser sees them, and each script's text."""

    def __init__(self, page: str) -> None:
        super().__init__()
        self.tags: list[str] = []
        self.attrs: list[tuple[str, str]] = []
        self.text: list[str] = []
        self.scripts: list[tuple[dict[str, str], str]] = []
        self._script: tuple[dict[str, str], list[str]] | None = None
        self.feed(page)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        self.attrs.extend((name, value or "") for name, value in attrs)
        if tag == "script":
            self._script = ({name: value or "" for name, value in attrs}, [])

    def handle_endtag(self, tag: str) -> None:
        if tag == "script" and self._script is not None:
            self.scripts.append((self._script[0], "".join(self._script[1])))
            self._script = None

    def handle_data(self, data: str) -> None:
        if self._script is not None:
            self._script[1].append(data)
        else:
            self.text.append(data)

    def plot_data(self) -> list[dict[str, Any]]:
        """The JSON blocks the timelines draw."""
        return [json.loads(text) for a, text in self.scripts if a.get("type") == "application/json"]


def csp_of(page: str) -> str:
    match = re.search(r'<meta http-equiv="Content-Security-Policy" content="([^"]*)">', page)
    assert match is not None
    return match.group(1)


def test_page_is_self_contained_and_runs_only_its_own_two_scripts() -> None:
    page = render(hostile_report(), Settings())
    csp = csp_of(page)
    assert "default-src 'none'" in csp and "unsafe-eval" not in csp
    script_src = next(d for d in csp.split(";") if d.strip().startswith("script-src"))
    allowed = set(script_src.split()[1:])
    markup = Markup(page)
    code = [text for attrs, text in markup.scripts if "type" not in attrs]
    assert len(code) == 2 and len(allowed) == 2  # uPlot and timeline.js, nothing else runs
    for text in code:
        digest = base64.b64encode(hashlib.sha256(text.encode()).digest()).decode()
        assert f"'sha256-{digest}'" in allowed
    assert all(a.get("type") in (None, "application/json") for a, _ in markup.scripts)
    assert not {"link", "iframe", "img", "object", "embed"} & set(markup.tags)
    names = {name for name, _ in markup.attrs}
    assert not {"src", "srcset", "xlink:href"} & names
    assert "@import" not in page and "url(" not in page
    # links (never fetched) go to the report's own sections or to the rules' references:
    # PX4's docs and source, MAVLink's definitions; never to a site the project does not run
    external = [v for n, v in markup.attrs if n == "href" and not v.startswith("#")]
    assert all(h.startswith(REFERENCE_PREFIXES[:3]) for h in external)
    assert "Copyright (c) 2022 Leon Sorokin" in code[0]  # uPlot's MIT notice travels with it


def test_recording_text_is_escaped_everywhere() -> None:
    page = render(hostile_report(), Settings())
    markup = Markup(page)
    assert "img" not in markup.tags
    assert len([t for t in markup.tags if t == "script"]) == len(markup.scripts)
    assert not [name for name, _ in markup.attrs if name.startswith("on")]
    # What the payloads said is there as text for the reader, or as data the script shows.
    assert any(SCRIPT in chunk for chunk in markup.text)
    data = json.dumps(markup.plot_data())
    assert "pwned" in data
    for attrs, text in markup.scripts:
        if attrs.get("type") == "application/json":
            assert "<" not in text and ">" not in text and "&" not in text


def test_script_data_cannot_close_its_element() -> None:
    hostile = {"text": "</script><script>alert(1)</script><!-- \u2028 & nan", "v": math.nan}
    text = as_script_data(hostile)
    assert "<" not in text and ">" not in text and "\u2028" not in text
    assert json.loads(text) == {"text": hostile["text"], "v": None}


def test_every_finding_has_a_row_and_every_timed_one_a_marker() -> None:
    report = hostile_report()
    page = render(report, Settings())
    marks = {m[4] for plot in Markup(page).plot_data() for m in plot["marks"]}
    for i, file in enumerate(report.files):
        for j, finding in enumerate(file.findings):
            assert f'id="finding-{i}-{j}"' in page
            timed = finding.time_s is not None and bool(file.timelines)
            assert (f"{i}-{j}" in marks) == timed
            assert (f'href="#mark-{i}-{j}"' in page) == timed
            assert f'href="#rule-{finding.code}"' in page and f'id="rule-{finding.code}"' in page


def test_long_series_are_downsampled_but_keep_their_spikes() -> None:
    times = [i * 0.02 for i in range(180_000)]  # one hour at 50 Hz
    times = [t for t in times if not 1800.0 < t < 1802.5]  # one 2.5 s gap
    times = [t for t in times if int(t) % 7 or t % 1 < 0.4]  # and a 0.6 s gap every 7 s
    values = [b - a for a, b in itertools.pairwise(times)]
    points = min_max_buckets(times[1:], values, times[-1])
    assert len(points) <= 2 * BUCKETS
    assert max(v for _, v in points) == max(values)
    file = FileReport("long.tlog", "tlog", Profile(), stats={"duration_s": times[-1]})
    with_plots(file, {"1": Timeline(keepalive=times)})
    file.findings = [Finding("OFB001", "x", Severity.ERROR, "gap", time_s=1800.0)]
    page = render(Report(files=[file]), Settings())
    (plot,) = Markup(page).plot_data()
    drawn = plot["keepalive"]
    assert len(drawn["t"]) <= 3 * BUCKETS and max(drawn["v"]) >= 2.5
    assert len(page) < 400_000


def test_loss_timeout_line_follows_the_profile_and_param(tmp_path: Path) -> None:
    recording = gap_recording(tmp_path / "gap.tlog")
    settings = replace(Settings(), px4="1.15")
    page = render(Report(files=[lint_file_with_timelines(recording, settings)]), settings)
    assert "COM_OF_LOSS_T = 1 s (PX4 1.15 default)" in page
    settings = replace(settings, params={"COM_OF_LOSS_T": 0.3})
    page = render(Report(files=[lint_file_with_timelines(recording, settings)]), settings)
    assert "COM_OF_LOSS_T = 0.3 s (set by the user)" in page
    (plot,) = Markup(page).plot_data()
    assert [0.3, "loss timeout (COM_OF_LOSS_T) 0.3 s", "loss"] in plot["keepalive"]["lines"]


def test_cli_html_has_a_timeline_per_vehicle(tmp_path: Path) -> None:
    recording = gap_recording(tmp_path / "gap.tlog")
    out = tmp_path / "report.html"
    result = run_cli(["lint", str(recording), "--format", "html", "--output", str(out)])
    assert result.returncode == 1, result.stderr
    page = out.read_text(encoding="utf-8")
    assert page.count('<figure class="timeline"') == 1
    (plot,) = Markup(page).plot_data()
    bands = [b["name"] for b in plot["bands"]]
    assert bands[:3] == ["signal (model)", "recorded mode", "predicted mode"]
    assert "set_position_target_local_ned" in bands


def test_a_gap_crosses_the_threshold_lines_when_the_keepalive_is_that_old() -> None:
    points = with_ramps([(0.05 * i, 0.05) for i in range(1, 40)] + [(5.0, 3.05)], 0.01)
    # On the log axis consecutive points are joined by straight segments: find where the
    # drawn curve crosses 0.5 s and 1 s; the newest keep-alive was at 1.95 s.
    for level in (0.5, 1.0):
        (t0, v0), (t1, v1) = next(
            (a, b) for a, b in itertools.pairwise(points) if a[1] < level <= b[1]
        )
        frac = (math.log(level) - math.log(v0)) / (math.log(v1) - math.log(v0))
        assert abs(t0 + frac * (t1 - t0) - (1.95 + level)) < 0.03


def test_loss_timeout_from_the_recording_when_the_engine_records_it() -> None:
    class Recorded(Timeline):  # what engine.Timeline carries once it copies the gate's params
        pass

    timeline = Recorded()
    timeline.loss_timeout = 0.7  # type: ignore[attr-defined]
    timeline.recorded_params = {"COM_OF_LOSS_T": 0.7}  # type: ignore[attr-defined]
    profile = Profile("1.15", "mc")
    assert timeline_loss_timeout(timeline, profile, Settings()) == (0.7, "from the recording")
    forced = replace(Settings(), params={"COM_OF_LOSS_T": 0.7})
    assert timeline_loss_timeout(timeline, profile, forced) == (0.7, "set by the user")
    from_file = replace(forced, param_origins={"COM_OF_LOSS_T": "/flights/pyproject.toml"})
    assert timeline_loss_timeout(timeline, profile, from_file) == (0.7, "set in pyproject.toml")
    assert timeline_loss_timeout(Timeline(), profile, Settings()) == (1.0, "PX4 1.15 default")


def test_each_vehicle_has_its_plot_and_its_own_markers() -> None:
    file = FileReport("fleet.mcap", "mcap", Profile(), stats={"duration_s": 10.0})
    with_plots(file, {
        "/px4_1": Timeline(keepalive=[0.1 * i for i in range(100)]),
        "/px4_2": Timeline(keepalive=[0.1 * i for i in range(50)]),
    })
    file.findings = [
        Finding("OFB001", "x", Severity.ERROR, "one", time_s=2.0, vehicle="/px4_1"),
        Finding("OFB001", "x", Severity.ERROR, "two", time_s=6.0, vehicle="/px4_2"),
        Finding("OFB002", "x", Severity.INFO, "whole file", time_s=1.0),
    ]
    page = render(Report(files=[file]), Settings())
    plots = Markup(page).plot_data()
    assert [p["name"] for p in plots] == ["vehicle /px4_1", "vehicle /px4_2"]
    assert [m[4] for m in plots[0]["marks"]] == ["0-0", "0-2"]
    assert [m[4] for m in plots[1]["marks"]] == ["0-1"]


def test_vehicle_names_are_shown_as_they_are_not_as_python_reprs(tmp_path: Path) -> None:
    recording = gap_recording(tmp_path / "gap.tlog")
    page = render(Report(files=[lint_file_with_timelines(recording, Settings())]), Settings())
    assert "<b>vehicle 1</b>" in page and "'1'" not in page
    assert "<dt>vehicles</dt><dd>1</dd>" in page


# --- what a recording holds beside the stream: where the vehicle was, what PX4 said, when -----


def _flight(path: Path) -> Path:
    """A tlog with the vehicle's position, PX4's messages, and a mode switch acked."""
    events: list[Event] = []
    for i in range(100):
        t = i * 0.05
        events.append(SetPositionTargetLocal(t=t, target_system=1, position=(0.0, 0.0, -2.0)))
        events.append(VehiclePosition(t=t + 0.01, vehicle="1", x=0.1 * i, y=0.0, z=-0.02 * i))
        if i % 20 == 0:
            events.append(VehicleStatus(t=t + 0.002, nav_state=14 if t > 1 else 2, armed=True))
    events += [
        Command(t=1.0, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0), target_system=1),
        CommandAck(t=1.004, command=176, result=0, target_system=255),
        StatusText(t=4.0, severity=4, text="Failsafe activated: <b>offboard</b> lost"),
    ]
    return write_tlog(path, sorted(events, key=lambda e: e.t))


def test_the_timeline_has_the_position_messages_and_labelled_commands(tmp_path: Path) -> None:
    recording = _flight(tmp_path / "flight.tlog")
    page = render(Report(files=[lint_file_with_timelines(recording, Settings())]), Settings())
    (plot,) = Markup(page).plot_data()
    t, altitude, x, _ = plot["position"]
    assert t[0] == 0.01 and altitude[-1] == 1.98 and x[-1] == 9.9  # NED: altitude is -z
    assert set(plot["setpoint"][1]) == {2.0}
    notes = {n[3]: n for n in plot["notes"]}
    assert notes["mode OFFBOARD ✓"][1:3] == ["cmd", "ok"]
    failsafe = next(n for n in plot["notes"] if n[1] == "failsafe")
    assert failsafe[2] == "warning" and "<b>offboard</b>" in failsafe[4]
    assert "<b>offboard" not in page  # sent as escaped JSON, shown as text by the script


def test_a_lint_judges_one_position_a_second_and_the_report_plots_every_one(
    tmp_path: Path,
) -> None:
    # OFB404 needs the vehicle's height on the ground; a lint decodes one position a second
    recording = _flight(tmp_path / "flight.tlog")  # 20 Hz for 5 s
    plain = lint_file(recording)
    assert plain.stats["kinds"]["vehicle_position"] == 5
    plotted = lint_file_with_timelines(recording, Settings())
    # the plots take the others beside the events: what is judged does not change
    assert plotted.stats == plain.stats and plotted.findings == plain.findings
    (timeline,) = plotted.timelines.values()
    plotted_t = [t for t, *_ in timeline.positions]
    assert len(plotted_t) > 50 and plotted_t == sorted(plotted_t)  # 20 Hz at most
    assert plotted_t[0] == 0.01 and plotted_t[-1] > 4.9


def test_the_recordings_start_on_the_wall_clock() -> None:
    def start(path: Path) -> str:
        page = render(Report(files=[lint_file_with_timelines(path, Settings())]), Settings())
        found = re.search(r"<dt>start</dt><dd>([^<]*)</dd>", page)
        assert found is not None
        return found.group(1)

    # the ULog's first GPS fix with UTC, less the time since the log started
    assert start(CORPORA / "real" / "sample_px4_events.ulg") == "2024-03-18 14:49:10.346 UTC"
    assert start(CORPORA / "tlog" / "stream_lost_in_offboard.tlog").endswith(" UTC")
    assert start(CORPORA / "real" / "sample.ulg").startswith("not in the recording")


def test_a_recorded_loss_timeout_of_zero_says_what_it_means() -> None:
    """sample.ulg (PX4 v1.6) names no release, so 1.15 is assumed, and records COM_OF_LOSS_T = 0:
    before 1.11 an extra wait after a fixed 500 ms, from 1.11 a signal lost at once."""
    log = CORPORA / "real" / "sample.ulg"
    page = render(Report(files=[lint_file_with_timelines(log, Settings())]), Settings())
    assert "COM_OF_LOSS_T = 0 s (from the recording): PX4 1.15 would count" in page
    assert "judge it with --px4 legacy" in page
    (plot,) = Markup(page).plot_data()
    assert plot["keepalive"] is None  # no stream: nothing to draw a line across
    legacy = replace(Settings(), px4="legacy")
    page = render(Report(files=[lint_file_with_timelines(log, legacy)]), legacy)
    assert "lost 500 ms after the newest keep-alive (fixed in PX4 before 1.11)" in page
    assert "COM_OF_LOSS_T = 0" not in page


def test_the_index_lists_every_recording_with_its_counts_and_rules() -> None:
    report = hostile_report()
    page = render(report, Settings())
    rows = re.findall(
        r'<tr class="sev-(\w+)" data-file="(file-\d+)" data-worst="\w+" data-rules="([^"]*)"', page
    )
    assert [(css, file) for css, file, _ in rows] == [("error", "file-0"), ("error", "file-1")]
    assert rows[0][2] == "OFB001 OFB002 OFB003" and rows[1][2] == "OFB001"
    assert '<option value="OFB003">OFB003</option>' in page


def test_the_vendored_plot_library_is_the_one_its_readme_names() -> None:
    vendor = ROOT / "fuzzoff" / "report" / "vendor"
    readme = (vendor / "README.md").read_text(encoding="utf-8")
    for name in ("uPlot.iife.min.js", "uPlot.min.css", "uPlot.LICENSE"):
        digest = hashlib.sha256((vendor / name).read_bytes()).hexdigest()
        assert f"{digest}  {name}" in readme
