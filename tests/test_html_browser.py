"""The HTML report in a real browser: headless Chromium driven over the DevTools protocol.

It opens offline with no console error and no request beyond its own file, shows the plot and
every finding, and hostile strings from a recording run no script. Screenshots are kept under
build/test-artifacts/.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path

import pytest

from fuzzoff.config import Settings
from fuzzoff.report.html import CSP, render
from fuzzoff.sources import find_recordings
from tests.cdp import Browser, find_chromium
from tests.helpers import CORPORA, ROOT, run_cli
from tests.report_fixtures import SCRIPT, gap_recording, hostile_report

ARTIFACTS = ROOT / "build" / "test-artifacts"


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


def open_report(browser: Browser, path: Path, screenshot: str) -> None:
    browser.open(path.resolve().as_uri())
    browser.screenshot(ARTIFACTS / screenshot)


def assert_clean_page(browser: Browser, page: Path) -> None:
    assert browser.console_messages() == []
    assert browser.requested_urls() == [page.resolve().as_uri()]
    assert browser.evaluate("document.title") == "fuzzoff report"


@pytest.mark.parametrize("with_csp", [True, False], ids=["with-csp", "escaping-alone"])
def test_hostile_strings_run_no_script(browser: Browser, tmp_path: Path, with_csp: bool) -> None:
    """The payloads would set document.title and log errors; escaping alone must stop them."""
    page = tmp_path / "hostile.html"
    text = render(hostile_report(), Settings())
    if not with_csp:
        text = text.replace(f'<meta http-equiv="Content-Security-Policy" content="{CSP}">', "")
        assert "Content-Security-Policy" not in text
    page.write_text(text, encoding="utf-8")
    open_report(browser, page, f"html-report-hostile-{'csp' if with_csp else 'no-csp'}.png")
    assert_clean_page(browser, page)
    assert browser.evaluate("document.querySelectorAll('script, img, iframe').length") == 0
    assert browser.evaluate("document.querySelectorAll('[onerror]').length") == 0
    # The payload is shown to the reader as text, not lost.
    assert SCRIPT in browser.evaluate("document.body.innerText")


def test_plot_and_every_finding_are_shown(browser: Browser, tmp_path: Path) -> None:
    report = hostile_report()
    page = tmp_path / "report.html"
    page.write_text(render(report, Settings()), encoding="utf-8")
    open_report(browser, page, "html-report-findings.png")
    assert_clean_page(browser, page)
    size = browser.evaluate(
        "(() => { const r = document.querySelector('svg.timeline').getBoundingClientRect();"
        " return [r.width, r.height]; })()"
    )
    assert size[0] > 500 and size[1] > 150
    assert browser.evaluate("document.querySelector('svg.timeline polyline') !== null")
    for i, file in enumerate(report.files):
        for j, finding in enumerate(file.findings):
            row = browser.evaluate(f"document.getElementById('finding-{i}-{j}').innerText")
            assert finding.code in row and finding.message.split("\x1b")[0] in row
            if finding.time_s is not None:
                width = browser.evaluate(
                    f"document.getElementById('mark-{i}-{j}').getBoundingClientRect().width"
                )
                assert width > 0
    # A finding's time links to its marker on the timeline, and the marker back to the row.
    browser.evaluate("document.querySelector('a[href=\"#mark-0-1\"]').click()")
    assert browser.evaluate("document.getElementById('mark-0-1').matches(':target')")
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
    assert_clean_page(browser, page)
    assert browser.evaluate("document.querySelectorAll('section.file').length") == len(paths)
    assert browser.evaluate("document.querySelectorAll('svg.timeline polyline').length") >= 1
    expected = sum(len(f["findings"]) for f in as_json["files"])
    assert (
        browser.evaluate("document.querySelectorAll('table.findings tbody tr').length") == expected
    )
