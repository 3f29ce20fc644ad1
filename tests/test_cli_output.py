"""Where reports go: --output for every format, standard output that is closed, full or cut
short by its reader, and paths that name nothing."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.helpers import CORPORA, ROOT, run_cli

LOST = CORPORA / "tlog" / "stream_lost_in_offboard.tlog"  # OFB101 and OFB103 errors: exit 1
GOOD = CORPORA / "tlog" / "good_offboard.tlog"  # exit 0


@pytest.mark.parametrize("fmt", ["terminal", "json"])
def test_output_into_a_missing_folder_creates_it(tmp_path: Path, fmt: str) -> None:
    target = tmp_path / "reports" / "today" / "lint.txt"
    result = run_cli(["lint", str(LOST), "--format", fmt, "-o", str(target)])
    assert result.returncode == 1 and result.stdout == ""
    assert "OFB103" in target.read_text()


@pytest.mark.parametrize("fmt", ["terminal", "json", "html"])
def test_output_that_is_a_folder_is_a_usage_error(tmp_path: Path, fmt: str) -> None:
    result = run_cli(["lint", str(LOST), "--format", fmt, "-o", str(tmp_path)])
    assert result.returncode == 2
    assert result.stderr.strip() == f"error: --output {tmp_path} is a folder: name a file"


@pytest.mark.parametrize("command", ["lint", "gate"])
def test_output_naming_the_recording_read_leaves_it_alone(tmp_path: Path, command: str) -> None:
    flight = tmp_path / "flight.tlog"
    flight.write_bytes(LOST.read_bytes())
    result = run_cli([command, str(flight), "--format", "json", "-o", str(flight)])
    assert result.returncode == 2 and "is a recording being read" in result.stderr
    assert flight.read_bytes() == LOST.read_bytes()


def test_output_dash_is_standard_output(tmp_path: Path) -> None:
    result = run_cli(["lint", str(LOST), "--format", "json", "-o", "-"], cwd=tmp_path)
    assert json.loads(result.stdout)["files"][0]["findings"]
    assert not (tmp_path / "-").exists()


@pytest.mark.parametrize("command", ["lint", "gate"])
def test_an_empty_path_is_not_the_current_folder(tmp_path: Path, command: str) -> None:
    """``fuzzoff lint "$LOGDIR"`` with the variable unset must not lint whatever is here."""
    (tmp_path / "other.tlog").write_bytes(LOST.read_bytes())
    result = run_cli([command, ""], cwd=tmp_path)
    assert result.returncode == 2 and result.stderr.strip() == "error: no such file or folder: ''"


def _shell(command: str) -> subprocess.CompletedProcess[str]:
    """A shell pipeline running ``fuzzoff`` as ``$F``; ``pipefail`` shows fuzzoff's status."""
    env = {**os.environ, "F": f"{sys.executable} -m fuzzoff.cli"}
    return subprocess.run(
        ["bash", "-c", f"set -o pipefail; {command}"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.mark.parametrize(
    ("command", "status"),
    [
        (f"$F lint {GOOD} {GOOD} {LOST} {LOST} | head -c1", 1),
        (f"$F lint {GOOD} {GOOD} {GOOD} | head -c1", 0),
        ("$F profiles | head -c1", 0),
        ("$F rule | head -c1", 0),
    ],
)
def test_a_reader_that_stops_early_leaves_the_status_alone(command: str, status: int) -> None:
    result = _shell(command)
    assert result.returncode == status, result.stderr
    assert "Traceback" not in result.stderr and "Broken pipe" not in result.stderr


@pytest.mark.parametrize("fmt", ["terminal", "json"])
def test_a_full_disk_is_one_line(fmt: str) -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    result = _shell(f"$F lint {LOST} --format {fmt} > /dev/full")
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "error: cannot write to standard output: No space left on device"
    ]


def test_a_closed_standard_output_is_one_line() -> None:
    result = _shell(f"$F lint {LOST} --format json >&-")
    assert result.returncode == 2
    assert "standard output is closed: name a file with --output" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize("command", [["profiles"], ["rule"]])
def test_tables_off_a_terminal_are_ascii(command: list[str]) -> None:
    text = run_cli(command).stdout
    assert text.isascii() and "|" in text


def test_one_lint_writes_several_reports(tmp_path: Path) -> None:
    """``--format``/``--output`` pairs: SARIF for code scanning, HTML as an artifact and the
    findings on standard output, from one lint, each the report a run of its own gives."""
    sarif, html, data = tmp_path / "out" / "f.sarif", tmp_path / "f.html", tmp_path / "f.json"
    both = run_cli(
        ["lint", str(LOST), "--format", "sarif", "-o", str(sarif), "--format", "html",
         "-o", str(html), "--format", "json", "-o", str(data), "--format", "terminal"]
    )
    alone = run_cli(["lint", str(LOST), "--format", "json"])
    assert both.returncode == alone.returncode == 1
    assert json.loads(data.read_text(encoding="utf-8")) == json.loads(alone.stdout)
    findings = json.loads(alone.stdout)["files"][0]["findings"]
    results = json.loads(sarif.read_text(encoding="utf-8"))["runs"][0]["results"]
    assert [r["ruleId"] for r in results] == [f["code"] for f in findings]
    page = html.read_text(encoding="utf-8")
    assert all(f'id="rule-{f["code"]}"' in page for f in findings)
    assert "fuzzoff summary" in both.stdout and "OFB101" in both.stdout


def test_an_output_goes_with_the_format_just_before_it(tmp_path: Path) -> None:
    """As the line reads: the text on the screen, the HTML in r.html."""
    result = run_cli(
        ["lint", str(LOST), "--format", "terminal", "--format", "html", "-o", "r.html"],
        cwd=tmp_path,
    )
    assert result.returncode == 1, result.stderr
    assert (tmp_path / "r.html").read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert "fuzzoff summary" in result.stdout and "<html" not in result.stdout


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["--format", "sarif", "--format", "html"], "only one report can go to standard output"),
        (["-o", "a.json", "-o", "b.json"], "-o a.json has no --format before it"),
        (["-o", "r.json", "--format", "json"], "-o r.json has no --format before it"),
        (["--format", "json", "-o", "a.json", "-o", "b.json"], "-o b.json has no --format"),
        (["--format", "json", "-o", "r", "--format", "sarif", "-o", "r"], "named twice"),
    ],
)
def test_reports_that_cannot_be_told_apart_are_a_usage_error(
    tmp_path: Path, args: list[str], says: str
) -> None:
    result = run_cli(["lint", str(LOST), *args], cwd=tmp_path)
    assert result.returncode == 2 and says in result.stderr
    assert result.stderr.count("\n") == 1 and not list(tmp_path.iterdir())
