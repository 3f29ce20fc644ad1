"""The HTML report as a document: self-contained, escaped, bounded in size (browser tests apart)."""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import replace
from html.parser import HTMLParser
from pathlib import Path

from fuzzoff.config import Settings
from fuzzoff.engine import Timeline
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.profiles import Profile
from fuzzoff.report.html import CSP, render
from fuzzoff.report.svg_timeline import MAX_BUCKETS, min_max_buckets, with_ramps
from fuzzoff.report.timelines import lint_one, loss_timeout
from tests.helpers import run_cli
from tests.report_fixtures import SCRIPT, gap_recording, hostile_report


class Markup(HTMLParser):
    """Every tag and attribute as a browser's parser sees them."""

    def __init__(self, page: str) -> None:
        super().__init__()
        self.tags: list[str] = []
        self.attrs: list[tuple[str, str]] = []
        self.text: list[str] = []
        self.feed(page)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        self.attrs.extend((name, value or "") for name, value in attrs)

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def test_page_is_self_contained_and_forbids_scripts_and_requests() -> None:
    page = render(hostile_report(), Settings())
    assert f'content="{CSP}"' in page and "script-src" not in CSP and "default-src 'none'" in CSP
    markup = Markup(page)
    assert not {"script", "link", "iframe", "img", "object", "embed"} & set(markup.tags)
    assert "svg" in markup.tags and "style" in markup.tags
    names = {name for name, _ in markup.attrs}
    assert not {"src", "srcset", "xlink:href"} & names
    assert "@import" not in page and "url(" not in page
    external = [v for n, v in markup.attrs if n == "href" and not v.startswith("#")]
    assert external and all(h.startswith("https://fuzzoff.dev/rules/") for h in external)


def test_recording_text_is_escaped_everywhere() -> None:
    markup = Markup(render(hostile_report(), Settings()))
    assert "script" not in markup.tags and "img" not in markup.tags
    assert not [name for name, _ in markup.attrs if name.startswith("on")]
    # What the payloads said is there as text for the reader.
    assert any(SCRIPT in chunk for chunk in markup.text)


def test_every_finding_has_a_row_and_every_timed_one_a_marker() -> None:
    report = hostile_report()
    page = render(report, Settings())
    for i, file in enumerate(report.files):
        for j, finding in enumerate(file.findings):
            assert f'id="finding-{i}-{j}"' in page
            timed = finding.time_s is not None and file.extras.get("timelines")
            assert (f'id="mark-{i}-{j}" href="#finding-{i}-{j}"' in page) == bool(timed)
            assert f'href="#rule-{finding.code}"' in page and f'id="rule-{finding.code}"' in page


def test_long_series_are_downsampled_but_keep_their_spikes() -> None:
    times = [i * 0.02 for i in range(180_000)]  # one hour at 50 Hz
    times = [t for t in times if not 1800.0 < t < 1802.5]  # one 2.5 s gap
    times = [t for t in times if int(t) % 7 or t % 1 < 0.4]  # and a 0.6 s gap every 7 s
    values = [b - a for a, b in itertools.pairwise(times)]
    points = min_max_buckets(times[1:], values, times[-1])
    assert len(points) <= 2 * MAX_BUCKETS
    assert max(v for _, v in points) == max(values)
    file = FileReport("long.tlog", "tlog", Profile(), stats={"duration_s": times[-1]})
    file.extras["timelines"] = {"1": Timeline(keepalive=times)}
    file.findings = [Finding("OFB001", "x", Severity.ERROR, "gap", time_s=1800.0)]
    page = render(Report(files=[file]), Settings())
    drawn = re.search(r'<polyline class="series" points="([^"]*)"', page)
    assert drawn is not None and len(drawn.group(1).split()) <= 3 * MAX_BUCKETS
    assert len(page) < 200_000


def test_loss_timeout_line_follows_the_profile_and_param(tmp_path: Path) -> None:
    recording = gap_recording(tmp_path / "gap.tlog")
    settings = replace(Settings(), px4="1.15")
    page = render(Report(files=[lint_one(recording, settings)]), settings)
    assert "COM_OF_LOSS_T = 1 s (PX4 1.15 default)" in page
    settings = replace(settings, params={"COM_OF_LOSS_T": 0.3})
    page = render(Report(files=[lint_one(recording, settings)]), settings)
    assert "COM_OF_LOSS_T = 0.3 s" in page and "loss timeout (COM_OF_LOSS_T) 0.3 s" in page


def test_cli_html_has_a_timeline_per_vehicle(tmp_path: Path) -> None:
    recording = gap_recording(tmp_path / "gap.tlog")
    out = tmp_path / "report.html"
    result = run_cli(["lint", str(recording), "--format", "html", "--output", str(out)])
    assert result.returncode == 1, result.stderr
    page = out.read_text(encoding="utf-8")
    assert page.count('<svg class="timeline"') == 1
    assert "recorded mode" in page and "predicted mode" in page
    assert "set_position_target_local_ned" in page


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
    assert loss_timeout(timeline, profile, Settings()) == (0.7, "from the recording")
    forced = replace(Settings(), params={"COM_OF_LOSS_T": 0.7})
    assert loss_timeout(timeline, profile, forced) == (0.7, "set by the user")
    from_file = replace(forced, param_origins={"COM_OF_LOSS_T": "/flights/pyproject.toml"})
    assert loss_timeout(timeline, profile, from_file) == (0.7, "set in pyproject.toml")
    assert loss_timeout(Timeline(), profile, Settings()) == (1.0, "PX4 1.15 default")


def test_each_vehicle_has_its_plot_and_its_own_markers() -> None:
    file = FileReport("fleet.mcap", "mcap", Profile(), stats={"duration_s": 10.0})
    file.extras["timelines"] = {
        "/px4_1": Timeline(keepalive=[0.1 * i for i in range(100)]),
        "/px4_2": Timeline(keepalive=[0.1 * i for i in range(50)]),
    }
    file.findings = [
        Finding("OFB001", "x", Severity.ERROR, "one", time_s=2.0, vehicle="/px4_1"),
        Finding("OFB001", "x", Severity.ERROR, "two", time_s=6.0, vehicle="/px4_2"),
        Finding("OFB002", "x", Severity.INFO, "whole file", time_s=1.0),
    ]
    page = render(Report(files=[file]), Settings())
    plots = page.split('<svg class="timeline"')[1:]
    assert len(plots) == 2
    assert 'id="mark-0-0"' in plots[0] and 'id="mark-0-1"' in plots[1]
    assert 'id="mark-0-2"' in plots[0] and 'id="mark-0-2"' not in plots[1]
