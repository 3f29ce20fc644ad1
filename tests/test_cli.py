"""The command line as users and scripts see it: exit status, usage errors, JSON shape, config."""

from __future__ import annotations

import json
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

from fuzzoff import commands
from fuzzoff.cli import main
from fuzzoff.commands import SUMMARIES
from tests.helpers import CORPORA, ROOT, run_cli, run_cli_process


def test_unknown_rule_selector_is_a_usage_error(tmp_path: Path) -> None:
    junk = tmp_path / "x.tlog"
    junk.write_bytes(b"\x00" * 64)
    result = run_cli(["lint", str(junk), "--select", "OFB9"])
    assert result.returncode == 2
    assert "OFB9" in result.stderr and "Traceback" not in result.stderr


def test_unknown_px4_version_is_a_usage_error(tmp_path: Path) -> None:
    result = run_cli(["lint", str(tmp_path), "--px4", "banana"])
    assert result.returncode == 2
    assert "unknown PX4 version" in result.stderr


def test_missing_path_is_a_usage_error() -> None:
    result = run_cli(["lint", "/no/such/flight.tlog"])
    assert result.returncode == 2
    assert "/no/such/flight.tlog" in result.stderr


@pytest.mark.parametrize(
    ("name", "content"),
    [("empty.tlog", b""), ("foreign.ulg", b"PK\x03\x04 this is a zip file, not a log" * 4)],
)
def test_unreadable_file_one_line_exit_2_and_json_still_written(
    tmp_path: Path, name: str, content: bytes
) -> None:
    path = tmp_path / name
    path.write_bytes(content)
    result = run_cli(["lint", str(path), "--format", "json"])
    assert result.returncode == 2
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and str(path) in lines[0]
    data = json.loads(result.stdout)
    assert data["tool"] == "fuzzoff"
    (file_report,) = data["files"]
    assert file_report["complete"] is False
    assert [f["code"] for f in file_report["findings"]] == ["OFB001"]


def test_json_shape_follows_the_interface(tmp_path: Path) -> None:
    path = tmp_path / "empty.mcap"
    path.write_bytes(b"")
    data = json.loads(run_cli(["lint", str(path), "--format", "json"]).stdout)
    assert set(data) >= {"tool", "version", "files"}
    file_report = data["files"][0]
    assert set(file_report) >= {"path", "format", "profile", "complete", "findings"}
    assert set(file_report["profile"]) >= {"px4", "vehicle", "detected"}
    finding = file_report["findings"][0]
    assert set(finding) >= {"code", "name", "severity", "message", "time_s", "location"}


@pytest.mark.parametrize(
    ("args", "header", "sources"),
    [
        ([], "PX4 1.15 (1.15.4) detected, mc detected", ("recording", "recording", True)),
        (
            ["--px4", "legacy"],
            "PX4 legacy set by the user (the recording says 1.15.4), mc detected",
            ("user", "recording", False),
        ),
        (["--px4", "1.15"], "PX4 1.15 (1.15.4) set by the user", ("user", "recording", False)),
    ],
)
def test_the_report_says_where_the_profile_came_from(
    args: list[str], header: str, sources: tuple[str, str, bool]
) -> None:
    """A profile forced on the command line is not 'detected', even where it agrees."""
    recording = str(CORPORA / "tlog" / "stream_lost_in_offboard.tlog")
    assert header in run_cli(["lint", recording, *args]).stdout
    profile = json.loads(run_cli(["lint", recording, *args, "--format", "json"]).stdout)["files"][
        0
    ]["profile"]
    assert (profile["px4_source"], profile["vehicle_source"], profile["detected"]) == sources


def test_config_unknown_key_is_a_usage_error(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text('[tool.fuzzoff]\npx4 = "1.15"\nselct = ["OFB1"]\n')
    (tmp_path / "a.tlog").write_bytes(b"")
    result = run_cli(["lint", "a.tlog"], cwd=tmp_path)
    assert result.returncode == 2
    assert "selct" in result.stderr


def test_config_from_pyproject_sets_the_profile(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text('[tool.fuzzoff]\npx4 = "1.16.2"\nvehicle = "fw"\n')
    (tmp_path / "a.tlog").write_bytes(b"")
    data = json.loads(run_cli(["lint", "a.tlog", "--format", "json"], cwd=tmp_path).stdout)
    assert data["files"][0]["profile"]["px4"] == "1.16"
    assert data["files"][0]["profile"]["vehicle"] == "fw"
    # the command line wins over the file
    data = json.loads(
        run_cli(["lint", "a.tlog", "--format", "json", "--px4", "1.13"], cwd=tmp_path).stdout
    )
    assert data["files"][0]["profile"]["px4"] == "1.13"


def test_rule_page_and_list() -> None:
    page = run_cli(["rule", "OFB101"])
    assert page.returncode == 0
    assert "keepalive-below-2hz" in page.stdout and "Why is this bad?" in page.stdout
    listing = json.loads(run_cli(["rule", "--format", "json"]).stdout)
    assert {"OFB001", "OFB101", "OFB201"} <= {r["code"] for r in listing}
    assert run_cli(["rule", "OFB999"]).returncode == 2


def test_profiles_lists_versions_and_vehicles() -> None:
    data = json.loads(run_cli(["profiles", "--format", "json"]).stdout)
    assert [p["profile"] for p in data["px4"]][:1] == ["legacy"]
    assert "rover-ackermann" in [v["type"] for v in data["vehicles"]]


def test_top_level_help_lists_every_command_without_importing_them() -> None:
    """``fuzzoff --help`` is the first thing a new user runs: every command and its summary,
    and none of the commands' modules (Hypothesis among them) loaded for it."""
    probe = (
        "import sys\n"
        "from fuzzoff.cli import main\n"
        "try:\n"
        "    main(['--help'])\n"
        "except SystemExit as exc:\n"
        "    assert exc.code == 0, exc.code\n"
        "heavy = ('fuzzoff.commands.', 'hypothesis')\n"
        "loaded = sorted(m for m in sys.modules if m.startswith(heavy))\n"
        "print('loaded:', loaded)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT
    )
    for name, summary in SUMMARIES.items():
        assert name in result.stdout
        assert summary.split()[0] in result.stdout
    assert "loaded: []" in result.stdout


def test_every_command_module_has_a_summary_and_its_own_help(
    capsys: pytest.CaptureFixture[str],
) -> None:
    modules = {m.name for m in pkgutil.iter_modules(commands.__path__) if m.name[0] != "_"}
    assert set(SUMMARIES) == modules
    for name in SUMMARIES:
        with pytest.raises(SystemExit) as exited:
            main([name, "--help"])
        assert exited.value.code == 0
        assert f"usage: fuzzoff {name}" in capsys.readouterr().out


def test_the_installed_command_runs_as_a_process(tmp_path: Path) -> None:
    path = tmp_path / "zero.ulg"
    path.write_bytes(b"")
    result = run_cli_process(["lint", str(path)])
    assert result.returncode == 2
    assert "Traceback" not in result.stderr


def test_px4_option_steers_the_bundled_definitions_of_a_bag_without_them() -> None:
    bag = CORPORA / "rosbag2" / "humble_no_definitions"
    right = json.loads(run_cli(["lint", str(bag), "--format", "json", "--px4", "1.14"]).stdout)
    assert right["files"][0]["complete"] is True
    wrong = run_cli(["lint", str(bag), "--format", "json", "--px4", "1.16"])
    assert wrong.returncode == 2
    (report,) = json.loads(wrong.stdout)["files"]
    assert report["complete"] is False
    assert any("bundled 1.16 definition" in f["message"] for f in report["findings"])


def test_a_bag_folder_without_metadata_is_linted_as_one_bag(tmp_path: Path) -> None:
    import shutil

    bag = tmp_path / "flight"
    bag.mkdir()
    shutil.copy(CORPORA / "rosbag2" / "two_vehicles" / "two_vehicles.db3", bag / "flight_0.db3")
    data = json.loads(run_cli(["lint", str(tmp_path), "--format", "json"]).stdout)
    assert [f["path"] for f in data["files"]] == [str(bag)]
    assert data["files"][0]["format"] == "rosbag2-sqlite3"
