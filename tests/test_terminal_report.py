"""The terminal report: grouping, summary, --quiet, --statistics, colour rules, hostile strings."""

from __future__ import annotations

import io
import json
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from rich.console import Console

from fuzzoff.events import Where
from fuzzoff.findings import FileReport, Finding, Report, Severity, Suppression, shorten
from fuzzoff.profiles import Profile
from fuzzoff.report.plain import plain_report
from fuzzoff.report.terminal import print_report
from tests.helpers import CORPORA, run_cli
from tests.report_fixtures import gap_recording, hostile_report

COLOUR = re.compile(r"\x1b\[[0-9;]*(?:3[0-9]|9[0-7])[0-9;]*m")
"""An SGR sequence that sets a foreground colour (30-39, 90-97)."""
INJECTED = ("\x1b[2J", "\x1b]0;", "\x07")


@pytest.fixture
def recordings(tmp_path: Path) -> tuple[Path, Path]:
    """A recording with errors (a gap while in OFFBOARD) and one that cannot be read at all."""
    broken = tmp_path / "evil\x1b[2J\x1b]0;pwned\x07.tlog"
    broken.write_bytes(b"not a recording at all")
    return gap_recording(tmp_path / "gap.tlog"), broken


@pytest.fixture
def no_colour_env(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("FORCE_COLOR", "NO_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE"):
        monkeypatch.delenv(name, raising=False)


def json_findings(paths: list[str]) -> list[dict[str, object]]:
    data = json.loads(run_cli(["lint", *paths, "--format", "json"]).stdout)
    return [f for file in data["files"] for f in file["findings"]]


def test_findings_grouped_per_file_then_summary(
    recordings: tuple[Path, Path], no_colour_env: None
) -> None:
    gap, broken = recordings
    result = run_cli(["lint", str(gap), str(broken)])
    assert result.returncode == 2  # one input could not be read
    out = result.stdout
    assert "\x1b" not in out  # not a terminal: plain text
    gap_at = out.index(str(gap))
    broken_at = out.index("evil\\x1b[2J")
    summary_at = out.index("fuzzoff summary")
    assert gap_at < broken_at < summary_at
    for finding in json_findings([str(gap)]):
        line = next(ln for ln in out[gap_at:broken_at].splitlines() if f" {finding['code']} " in ln)
        assert str(finding["severity"]) in line
        if finding["time_s"] is not None:
            assert f"{finding['time_s']:.3f}s" in line
        assert str(finding["summary"]) in line  # the key fact, not the whole explanation
        assert str(finding["message"]) not in line
        location = finding["location"]
        if isinstance(location, dict):
            assert f"  {location['topic']} #{location['index']}" in line
            assert f"@{location['offset']}" not in line  # the byte offset is --verbose's
    assert "result: incomplete input" in out


def test_escape_sequences_from_a_recording_never_reach_the_terminal(
    recordings: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    _, broken = recordings
    monkeypatch.setenv("FORCE_COLOR", "1")
    monkeypatch.delenv("NO_COLOR", raising=False)
    result = run_cli(["lint", str(broken), "--no-progress"])
    assert COLOUR.search(result.stdout)  # rich's own colours are there...
    for text in (result.stdout, result.stderr):
        assert not any(seq in text for seq in INJECTED)  # ...the file's are not
        assert "evil\\x1b[2J\\x1b]0;pwned\\x07.tlog" in text


def test_hostile_strings_in_findings_are_neutralised() -> None:
    buffer = io.StringIO()
    console = Console(file=buffer, force_terminal=True, width=200)
    print_report(console, hostile_report(), Severity.WARNING)
    print_report(console, hostile_report(), Severity.WARNING, verbose=True)
    out = buffer.getvalue()
    assert COLOUR.search(out)
    assert "\x1b[2J" not in out and "\\x1b[2J" in out


def test_no_color_turns_colour_off_even_when_forced(
    recordings: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    gap, _ = recordings
    monkeypatch.setenv("FORCE_COLOR", "1")
    monkeypatch.setenv("NO_COLOR", "1")
    result = run_cli(["lint", str(gap), "--no-progress"])
    assert "OFB" in result.stdout and not COLOUR.search(result.stdout)


def test_quiet_keeps_only_findings_at_the_fail_level(
    recordings: tuple[Path, Path], no_colour_env: None
) -> None:
    gap, _ = recordings
    findings = json_findings([str(gap)])
    result = run_cli(["lint", str(gap), "--quiet"])
    lines = [ln for ln in result.stdout.splitlines() if re.search(r" OFB\d{3} ", ln)]
    expected = [f for f in findings if f["severity"] in ("error", "warning")]
    assert expected and len(lines) == len(expected)
    assert all(" info " not in ln for ln in lines)
    assert "fuzzoff summary" not in result.stdout
    quiet_pass = run_cli(["lint", str(gap), "--quiet", "--select", "OFB003"])
    assert quiet_pass.returncode == 0 and quiet_pass.stdout.strip() == ""


def test_statistics_counts_per_rule(recordings: tuple[Path, Path], no_colour_env: None) -> None:
    gap, broken = recordings
    findings = json_findings([str(gap), str(broken)])
    result = run_cli(["lint", str(gap), str(broken), "--statistics"])
    rows = [ln.split() for ln in result.stdout.splitlines() if ln.strip()]
    counts = {row[1]: int(row[0]) for row in rows}
    expected: dict[str, int] = {}
    for f in findings:
        expected[str(f["code"])] = expected.get(str(f["code"]), 0) + 1
    assert counts == expected
    assert [int(r[0]) for r in rows] == sorted((int(r[0]) for r in rows), reverse=True)
    assert "fuzzoff summary" not in result.stdout and str(gap) not in result.stdout


def test_a_finding_is_one_short_line_with_its_details_behind_verbose(
    recordings: tuple[Path, Path], no_colour_env: None
) -> None:
    gap, _ = recordings
    findings = json_findings([str(gap)])
    plain = run_cli(["lint", str(gap)]).stdout
    verbose = run_cli(["lint", str(gap), "--verbose"]).stdout
    finding_lines = [ln for ln in plain.splitlines() if re.search(r" OFB\d{3} ", ln)]
    assert len(finding_lines) == len(findings)
    assert all(len(ln) <= 140 for ln in finding_lines), finding_lines
    assert "--verbose shows each finding in full" in plain
    for finding in findings:
        assert str(finding["message"]) not in plain
        assert str(finding["message"]) in verbose
        location = finding["location"]
        if isinstance(location, dict) and "offset" in location:
            assert f"@{location['offset']}" in verbose
    # one vehicle: named once in the heading, not on every line
    assert ", vehicle 1" in plain.splitlines()[0] and "[1]" not in plain
    assert "--verbose shows" not in verbose


def test_several_vehicles_are_named_on_each_line(no_colour_env: None) -> None:
    bag = CORPORA / "rules_mavlink" / "ofb607_second_vehicle_target.tlog"
    out = run_cli(["lint", str(bag)]).stdout
    lines = [ln for ln in out.splitlines() if re.search(r" OFB\d{3} ", ln)]
    vehicles = {f["vehicle"] for f in json_findings([str(bag)]) if f["vehicle"]}
    assert len(vehicles) > 1
    for vehicle in vehicles:
        assert any(f"[{vehicle}] " in ln for ln in lines), vehicle


def test_on_a_terminal_a_long_line_wraps_at_a_word_under_its_own_column() -> None:
    words = " ".join(f"word{i:02d}" for i in range(30))
    report = Report(
        files=[
            FileReport(
                path="flight.tlog",
                format="tlog",
                profile=Profile(),
                findings=[
                    Finding(
                        "OFB101",
                        "keepalive-below-2hz",
                        Severity.ERROR,
                        "long",
                        time_s=1.0,
                        summary=words,
                        where=Where("/fmu/in/offboard_control_mode", index=81),
                    )
                ],
            )
        ]
    )
    buffer = io.StringIO()
    print_report(Console(file=buffer, force_terminal=True, width=80), report, Severity.WARNING)
    text = re.sub(r"\x1b\[[0-9;]*m", "", buffer.getvalue())
    rows = [ln for ln in text.splitlines() if "word" in ln]
    assert len(rows) > 1 and all(len(ln) <= 80 for ln in rows)
    for row in rows[1:]:
        assert row.startswith(" " * 26) and re.match(r"^ +word\d\d( |$)", row)
    assert " ".join(" ".join(rows).split()).endswith(words.split()[-1])
    # the place is never broken across rows: it gets a row of its own when it does not fit
    place = next(ln for ln in text.splitlines() if "offboard_control_mode" in ln)
    assert place.strip() == "/fmu/in/offboard_control_mode #81"


def test_summaries_keep_the_key_fact_and_json_keeps_both(no_colour_env: None) -> None:
    recording = CORPORA / "tlog" / "stream_lost_in_offboard.tlog"
    findings = {str(f["code"]): f for f in json_findings([str(recording)])}
    assert findings["OFB101"]["summary"] == (
        "keep-alive gap 2.00 s in OFFBOARD; PX4 1.15 loses the signal at 1.00 s"
    )
    assert str(findings["OFB101"]["message"]).startswith("keep-alive gap of 2.00 s in OFFBOARD")
    assert "docs: keep-alive at > 2 Hz" in str(findings["OFB101"]["message"])
    assert findings["OFB103"]["summary"] == (
        "keep-alive stopped at 8.00 s: POSCTL 9.01-9.11 s; recorded: POSCTL 9.00-10.00 s"
        " (1 Hz status)"
    )
    assert findings["OFB701"]["summary"] == (
        "on a 1 s stream loss: POSCTL, back to OFFBOARD when it resumes"
    )


def test_shorten_takes_the_first_statement_and_never_cuts_a_word() -> None:
    assert shorten("gap of 2 s (until it left); docs: 2 Hz") == "gap of 2 s (until it left)"
    assert shorten("VehicleControlMode: payload of 27 bytes") == "VehicleControlMode"
    long = "a setpoint (with a long aside that says a great deal) " + "word " * 30
    short = shorten(long, 60)
    assert len(short) <= 60 and short.endswith("\u2026") and "aside" not in short
    assert all(w == "a" or w == "setpoint" or w.startswith("word") for w in short[:-1].split())


def _rich_text(report: Report, width: int, **options: Any) -> str:
    """What ``print_report`` draws on a console of ``width`` that is not a terminal."""
    buffer = io.StringIO()
    console = Console(file=buffer, highlight=False, force_terminal=False, width=width)
    print_report(console, report, options.pop("fail_on", Severity.WARNING), **options)
    return buffer.getvalue()


def _many_kinds() -> Report:
    """Several vehicles, suppressed findings, an incomplete file, a file without findings."""
    suppressed = Suppression(kind="config", reason="known", source="fuzzoff.toml")
    baseline = Suppression(kind="baseline", reason="old", source="base.json")
    one = Finding("OFB101", "x", Severity.ERROR, "a gap of 2.0 s in the stream", time_s=1234.5)
    busy = FileReport(
        path="flights/two vehicles.tlog",
        format="tlog",
        profile=Profile("1.15", "mc"),
        findings=[
            Finding("OFB101", "x", Severity.ERROR, "short " * 40, time_s=1.0, vehicle="1"),
            Finding("OFB203", "y", Severity.WARNING, "warn", time_s=2.0, end_s=4.5, vehicle="2"),
            Finding("OFB005", "z", Severity.INFO, "info", where=Where("HEARTBEAT", 3, 99)),
        ],
        suppressed=[(one, suppressed), (one, baseline), (one, baseline)],
    )
    quiet_file = FileReport(path="clean.ulg", format="ulog", profile=Profile("1.16", "rover"))
    broken = FileReport(path="cut.mcap", format="mcap", profile=Profile(), complete=False)
    return Report(files=[busy, quiet_file, broken])


@pytest.mark.parametrize("width", [80, 160, 50, 20])
@pytest.mark.parametrize(
    "options",
    [
        {},
        {"verbose": True},
        {"quiet": True},
        {"exit_zero": True},
        {"fail_on": Severity.INFO},
        {"fail_on": Severity.ERROR, "verbose": True},
    ],
    ids=repr,
)
@pytest.mark.parametrize("make", [hostile_report, _many_kinds])
def test_the_plain_text_is_what_rich_draws_off_a_terminal(
    make: Callable[[], Report], options: dict[str, Any], width: int
) -> None:
    """Off a terminal the report is written without rich (issue 31): the same text, or rich
    draws it (None) where a line would wrap at the console's width."""
    report = make()
    plain = plain_report(
        report,
        options.get("fail_on", Severity.WARNING),
        width,
        **{k: v for k, v in options.items() if k != "fail_on"},
    )
    if plain is None:
        assert width < 80  # only a narrow console is left to rich
    else:
        assert plain == _rich_text(report, width, **dict(options))
    assert plain_report(report, Severity.WARNING, width, statistics=True) is None


@pytest.mark.parametrize(
    "args",
    [
        ["corpora/real/sample_log_small.ulg", "--verbose"],
        ["corpora/tlog", "--quiet"],
        ["corpora/rules", "--exit-zero"],
        [
            "corpora/ros2bridge/example_agent_restart-1.16.2-ros2-mcap",
            "--with",
            "corpora/ros2bridge/example_agent_restart-1.16.2-ros2.ulg",
        ],
    ],
    ids=lambda a: a[0],
)
def test_a_lint_off_a_terminal_prints_what_rich_printed(
    args: list[str], no_colour_env: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    root = Path(__file__).resolve().parent.parent
    plain = run_cli(["lint", *args], cwd=root)
    monkeypatch.setattr("fuzzoff.report.plain.plain_width", lambda to_file: None)
    drawn = run_cli(["lint", *args], cwd=root)
    assert plain.stdout and plain.stdout == drawn.stdout
    assert plain.returncode == drawn.returncode


def test_a_report_written_to_a_file_is_what_rich_wrote(
    tmp_path: Path, no_colour_env: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--output FILE``: the plain text at rich's file width (160), without rich."""
    args = ["lint", str(CORPORA / "tlog"), "--verbose", "--exit-zero"]
    run_cli([*args, "--format", "terminal", "--output", str(tmp_path / "plain.txt")])
    monkeypatch.setattr("fuzzoff.report.plain.plain_width", lambda to_file: None)
    run_cli([*args, "--format", "terminal", "--output", str(tmp_path / "rich.txt")])
    plain = (tmp_path / "plain.txt").read_text()
    assert plain and plain == (tmp_path / "rich.txt").read_text()
