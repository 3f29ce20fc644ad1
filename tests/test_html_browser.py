"""The HTML report in a real browser: headless Chromium driven over the DevTools protocol.

It opens offline with no console error and no request beyond its own file, runs only its own
scripts, shows the plots and every finding, and hostile strings from a recording run no
script. At two widths the labels a user reads do not overlap, the timelines fit the page, and
zooming changes what they show. Screenshots are kept under build/test-artifacts/.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.config import Settings
from fuzzoff.engine import Timeline, lint_file_with_timelines
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.formats import find_recordings
from fuzzoff.profiles import Profile
from fuzzoff.report.html import render
from fuzzoff.report.html_assets import report_csp
from tests.cdp import Browser, find_chromium
from tests.helpers import CORPORA, ROOT, run_cli
from tests.report_fixtures import SCRIPT, gap_recording, hostile_report, with_plots

ARTIFACTS = ROOT / "build" / "test-artifacts"
WIDTHS = (1280, 760)


@pytest.fixture
def browser() -> Iterator[Browser]:
    executable = find_chromium()
    if executable is None:
        reason = "chromium is not installed (`make test` installs it: apt-get install chromium)"
        if os.environ.get("CI"):
            pytest.fail(reason)
        pytest.skip(reason)
    with Browser(executable) as b:
        yield b


def open_report(browser: Browser, path: Path, screenshot: str, width: int = 1200) -> None:
    browser.set_width(width)
    browser.open(path.resolve().as_uri())
    browser.wait_until(
        "document.querySelector('figure.timeline') === null || "
        "document.querySelector('figure.timeline .uplot') !== null"
    )
    browser.screenshot(ARTIFACTS / screenshot, whole=False)


def assert_clean_page(browser: Browser, page: Path) -> None:
    assert browser.console_messages() == []
    assert browser.requested_urls() == [page.resolve().as_uri()]
    assert browser.evaluate("document.title") == "fuzzoff report"


def build_all(browser: Browser) -> int:
    """Bring every timeline into view once, so that each is drawn; how many there are."""
    count: int = browser.evaluate("document.querySelectorAll('figure.timeline').length")
    for i in range(count):
        browser.evaluate(f"document.querySelectorAll('figure.timeline')[{i}].scrollIntoView()")
        assert browser.wait_until(
            f"document.querySelectorAll('figure.timeline')[{i}].querySelector('.uplot') !== null"
        )
    return count


@pytest.mark.parametrize("with_csp", [True, False], ids=["with-csp", "escaping-alone"])
def test_hostile_strings_run_no_script(browser: Browser, tmp_path: Path, with_csp: bool) -> None:
    """The payloads would set document.title and log errors; escaping alone must stop them."""
    page = tmp_path / "hostile.html"
    text = render(hostile_report(), Settings())
    if not with_csp:
        text = text.replace(
            f'<meta http-equiv="Content-Security-Policy" content="{report_csp()}">', ""
        )
        assert "Content-Security-Policy" not in text
    page.write_text(text, encoding="utf-8")
    open_report(browser, page, f"html-report-hostile-{'csp' if with_csp else 'no-csp'}.png")
    build_all(browser)
    assert_clean_page(browser, page)
    assert browser.evaluate("document.querySelectorAll('img, iframe').length") == 0
    assert browser.evaluate("document.querySelectorAll('[onerror]').length") == 0
    # the page's two scripts and its data blocks, no script from a recording
    assert (
        browser.evaluate("[...document.scripts].filter(s => s.type !== 'application/json').length")
        == 2
    )
    # The payload is shown to the reader as text, not lost: in the table and on the timeline.
    assert SCRIPT in browser.evaluate("document.body.innerText")
    notes = browser.evaluate(
        "[...document.querySelectorAll('.note')].map(n => n.title + n.textContent).join()"
    )
    assert SCRIPT in notes


def test_plot_and_every_finding_are_shown(browser: Browser, tmp_path: Path) -> None:
    report = hostile_report()
    page = tmp_path / "report.html"
    page.write_text(render(report, Settings()), encoding="utf-8")
    open_report(browser, page, "html-report-findings.png")
    build_all(browser)
    assert_clean_page(browser, page)
    size = browser.evaluate(
        "(() => { const r = document.querySelector('figure.timeline .uplot')"
        ".getBoundingClientRect(); return [r.width, r.height]; })()"
    )
    assert size[0] > 500 and size[1] > 150
    for i, file in enumerate(report.files):
        for j, finding in enumerate(file.findings):
            row = browser.evaluate(f"document.getElementById('finding-{i}-{j}').innerText")
            assert finding.code in row and finding.message.split("\x1b")[0] in row
            if finding.time_s is not None and file.timelines:
                shown = browser.evaluate(
                    f"(() => {{ const m = document.getElementById('mark-{i}-{j}');"
                    " return m !== null && (!m.hidden || [...document.querySelectorAll("
                    f"'.mark.group')].some(g => g.title.includes('{finding.code}'))); }})()"
                )
                assert shown
    # A finding's time links to its marker, which comes into view, and the marker to the row.
    browser.evaluate("document.querySelector('a[href=\"#mark-0-1\"]').click()")
    assert browser.wait_until(
        "(() => { const m = document.getElementById('mark-0-1');"
        " return m.matches(':target') && !m.hidden && m.getBoundingClientRect().width > 0; })()"
    )
    assert (
        browser.evaluate("document.getElementById('mark-0-1').getAttribute('href')")
        == "#finding-0-1"
    )
    # Its rule page is embedded.
    assert "Why is this bad?" in browser.evaluate(
        "document.getElementById('rule-OFB001').innerText"
    )


def _corpus_recordings() -> list[Path]:
    """One recording per corpus folder (each format once), when the corpora exist."""
    if not CORPORA.is_dir():
        return []
    folders = sorted(p for p in CORPORA.iterdir() if p.is_dir())
    return [found[0] for found in map(find_recordings, folders) if found]


def test_cli_html_of_real_recordings(browser: Browser, tmp_path: Path) -> None:
    paths = [gap_recording(tmp_path / "gap.tlog"), *_corpus_recordings()]
    page = tmp_path / "lint.html"
    args = ["lint", *map(str, paths), "--px4", "1.15", "--vehicle", "mc"]
    result = run_cli([*args, "--format", "html", "--output", str(page)])
    assert result.returncode in (0, 1, 2), result.stderr
    as_json = json.loads(run_cli([*args, "--format", "json"]).stdout)
    open_report(browser, page, "html-report-cli.png")
    assert browser.evaluate("document.querySelectorAll('section.file').length") == len(paths)
    assert build_all(browser) >= len(paths) - 1
    assert_clean_page(browser, page)
    assert browser.evaluate("document.querySelectorAll('.keepalive').length") >= 1
    expected = sum(len(f["findings"]) for f in as_json["files"])
    assert (
        browser.evaluate("document.querySelectorAll('table.findings tbody tr').length") == expected
    )


# --- what a user sees, at two widths ----------------------------------------------------------


def crowded_file() -> FileReport:
    """A minute of stream with 120 findings in two bursts: too many to draw one by one."""
    file = FileReport("crowded.tlog", "tlog", Profile("1.15", "mc"), stats={"duration_s": 60.0})
    with_plots(file, {"1": Timeline(keepalive=[i * 0.05 for i in range(1200)])})
    file.findings = [
        Finding("OFB101", "x", Severity.WARNING, f"gap {k}", time_s=10.0 + k * 0.05, vehicle="1")
        for k in range(60)
    ] + [
        Finding("OFB103", "x", Severity.ERROR, f"loss {k}", time_s=40.0 + k * 0.02, vehicle="1")
        for k in range(60)
    ]
    return file


@pytest.fixture(scope="module")
def user_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Recordings with what a user meets: a gap, a real log with PX4's messages and positions,
    a ROS 2 flight, PX4 1.17's ground-station log of a failsafe, and a crowd of findings."""
    folder = tmp_path_factory.mktemp("user")
    paths = [
        gap_recording(folder / "gap.tlog"),
        CORPORA / "real" / "sample_px4_events.ulg",
        CORPORA / "tlog" / "stream_lost_in_offboard.tlog",
        CORPORA / "mcap" / "stream_lost.mcap",
        CORPORA / "tlog" / "px4_1_17_0_loss.gcs.tlog",  # PX4 1.17 SITL's own failsafe message
    ]
    files = [lint_file_with_timelines(p, Settings()) for p in paths if p.exists()]
    page = folder / "report.html"
    page.write_text(render(Report(files=[*files, crowded_file()]), Settings()), "utf-8")
    return page


OVERLAPS = """(() => {
  const boxes = (els) => [...els].filter((e) => !e.hidden && e.offsetParent !== null)
    .map((e) => e.getBoundingClientRect()).filter((r) => r.width > 0);
  const hit = (a, b) => a.left < b.right - 0.5 && b.left < a.right - 0.5 &&
    a.top < b.bottom - 0.5 && b.top < a.bottom - 0.5;
  const pairs = (rects) => { let n = 0; rects.forEach((a, i) => rects.slice(i + 1)
    .forEach((b) => { if (hit(a, b)) n++; })); return n; };
  const out = {};
  document.querySelectorAll('figure.timeline').forEach((fig, k) => {
    if (!fig.querySelector('.uplot')) return;
    const labels = boxes(fig.querySelectorAll('.note:not([hidden]) .label, .row-name'));
    const ticks = boxes(fig.querySelectorAll('.note:not([hidden]) .tick'));
    const marks = boxes(fig.querySelectorAll('.mark'));
    const texts = boxes(fig.querySelectorAll('figcaption, .toolbar > *, .readout'));
    out[k] = pairs(labels) + pairs(marks) + pairs(texts) +
      labels.reduce((n, l) => n + ticks.filter((t) => hit(l, t)).length, 0);
  });
  return out;
})()"""


@pytest.mark.parametrize("width", WIDTHS)
def test_what_a_user_sees_at_two_widths(browser: Browser, user_report: Path, width: int) -> None:
    open_report(browser, user_report, f"html-report-{width}-top.png", width)
    figures = build_all(browser)
    assert figures >= 4
    # The timelines fit the page: no plot wider than its figure, nothing to scroll sideways.
    assert browser.evaluate("document.documentElement.scrollWidth") <= width
    assert browser.evaluate(
        "[...document.querySelectorAll('figure.timeline')].every((f) => {"
        " const r = f.getBoundingClientRect(); return [...f.querySelectorAll('.uplot')]"
        ".every((u) => u.getBoundingClientRect().right <= r.right + 0.5); })"
    )
    # No two labels a user reads overlap: markers, PX4's messages, commands, the toolbar.
    assert set(browser.evaluate(OVERLAPS).values()) == {0}
    # The real log shows PX4's own messages and the labelled commands, with its date.
    real = "[...document.querySelectorAll('figure.timeline')].find((f) => f.getAttribute("
    real += "'aria-label').includes('sample_px4_events'))"
    labels = browser.evaluate(
        f"[...{real}.querySelectorAll('.note .label')].filter((l) => !l.hidden)"
        ".map((l) => l.textContent)"
    )
    assert any(label.startswith("[commander]") for label in labels)
    assert any(label == "takeoff" or label.startswith("mode ") for label in labels)
    assert "2024-03-18" in browser.evaluate(f"{real}.closest('section').innerText")
    assert browser.evaluate(f"{real}.querySelector('.position') !== null")
    # PX4's failsafe message has a row of its own, and its label is whole
    failsafe = browser.evaluate(
        "[...document.querySelectorAll('.note.failsafe')].filter((n) => !n.hidden)"
        ".map((n) => { const l = n.querySelector('.label');"
        " return [l.hidden, l.textContent, l.scrollWidth <= l.clientWidth + 1]; })"
    )
    assert failsafe and all(not hidden and whole for hidden, _, whole in failsafe)
    assert any(text.startswith("Failsafe activated") for _, text, _ in failsafe)
    browser.evaluate(f"{real}.scrollIntoView()")
    browser.screenshot(ARTIFACTS / f"html-report-{width}-real.png", real)
    _zoom_changes_the_visible_range(browser, width)


def _view(browser: Browser, fig: str) -> list[float]:
    view: list[float] = [float(v) for v in browser.evaluate(f"{fig}.dataset.view").split()]
    return view


def _zoom_changes_the_visible_range(browser: Browser, width: int) -> None:
    fig = "[...document.querySelectorAll('figure.timeline')].at(-1)"  # the crowded one
    browser.evaluate(f"{fig}.scrollIntoView()")
    assert _view(browser, fig) == [0.0, 60.0]
    text = browser.evaluate(f"{fig}.querySelector('.range').textContent")
    assert text.startswith("showing 0.0–60.0 s of 60.0 s")
    # 120 findings are drawn as a few groups, each readable
    groups = browser.evaluate(f"{fig}.querySelectorAll('.mark.group').length")
    shown = browser.evaluate(f"[...{fig}.querySelectorAll('.mark')].filter(m => !m.hidden).length")
    assert groups >= 1 and shown <= 10
    browser.screenshot(ARTIFACTS / f"html-report-{width}-crowded.png", fig)
    # the + button halves the span around its middle
    browser.evaluate(f"{fig}.querySelector('.toolbar button:nth-child(2)').click()")
    assert _view(browser, fig) == [15.0, 45.0]
    assert browser.evaluate(f"{fig}.querySelector('.range').textContent").startswith(
        "showing 15.0–45.0 s"
    )
    # Ctrl + wheel over the keep-alive plot zooms in around the pointer
    over = browser.evaluate(
        f"(() => {{ const r = {fig}.querySelector('.keepalive .u-over').getBoundingClientRect();"
        " return [r.left, r.top, r.width, r.height]; })()"
    )
    x, y = over[0] + over[2] * 0.5, over[1] + over[3] * 0.5
    browser.mouse("mouseWheel", x, y, deltaX=0, deltaY=-120, modifiers=2)
    a, b = _view(browser, fig)
    assert b - a < 30.0 and a < 30.0 < b
    # dragging across a plot zooms to what was dragged over
    browser.mouse("mousePressed", over[0] + over[2] * 0.25, y, button="left", clickCount=1)
    browser.mouse("mouseMoved", over[0] + over[2] * 0.5, y, button="left", buttons=1)
    browser.mouse("mouseReleased", over[0] + over[2] * 0.5, y, button="left", clickCount=1)
    c, d = _view(browser, fig)
    assert a < c < d < b and abs((d - c) - (b - a) / 4) < (b - a) * 0.02
    # every plot of the vehicle follows
    spans = browser.evaluate(f"[...{fig}.querySelectorAll('.uplot')].length")
    assert spans >= 2
    # clicking a group zooms in until its findings can be told apart
    browser.evaluate(f"{fig}.querySelector('.toolbar button:nth-child(5)').click()")
    browser.evaluate(f"{fig}.querySelector('.mark.group').click()")
    a, b = _view(browser, fig)
    assert b - a < 10.0
    assert set(browser.evaluate(OVERLAPS).values()) == {0}
    browser.screenshot(ARTIFACTS / f"html-report-{width}-zoomed.png", fig)


def test_the_index_sorts_and_filters(browser: Browser, user_report: Path) -> None:
    open_report(browser, user_report, "html-report-index.png")
    rows = "[...document.querySelectorAll('table.index tbody tr')]"
    visible = f"{rows}.filter(r => !r.hidden)"

    def column(n: int) -> list[Any]:
        values: list[Any] = browser.evaluate(f"{visible}.map(r => r.cells[{n}].textContent)")
        return values

    total = len(column(0))
    assert total == 6
    errors = "document.querySelector('table.index th:nth-child(6) button')"
    browser.evaluate(f"{errors}.click()")
    ascending = [int(v) for v in column(5)]
    assert ascending == sorted(ascending)
    browser.evaluate(f"{errors}.click()")
    assert [int(v) for v in column(5)] == sorted(ascending, reverse=True)
    assert column(0)[0] == "crowded.tlog"

    def choose(name: str, value: str) -> None:
        browser.evaluate(
            f"(() => {{ const c = document.querySelector('.index-controls [name={name}]');"
            f" c.value = {json.dumps(value)}; c.dispatchEvent(new Event('input')); }})()"
        )

    choose("rule", "OFB103")
    names = column(0)
    assert names and "crowded.tlog" in names and len(names) < total
    assert all("OFB103" in r for r in column(8))
    hidden_sections = browser.evaluate(
        "[...document.querySelectorAll('section.file')].filter(s => s.hidden).length"
    )
    assert hidden_sections == total - len(names)
    choose("rule", "")
    choose("severity", "error")
    assert all(int(v) > 0 for v in column(5))
    choose("severity", "")
    choose("text", "sample_px4")
    assert column(0) == ["corpora/real/sample_px4_events.ulg"] or len(column(0)) == 1
    assert (
        browser.evaluate("document.querySelector('.index-controls .count').textContent")
        == f"1 of {total} recordings"
    )
