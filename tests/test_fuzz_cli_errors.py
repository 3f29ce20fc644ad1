"""``fuzzoff fuzz`` and ``fuzzoff replay`` given what they cannot use: one line naming what is
wrong and exit status 2, never a traceback, a hang or a success that checked nothing."""

from __future__ import annotations

import json
import shutil
import socket
from collections.abc import Callable
from pathlib import Path
from typing import Any
from urllib.parse import unquote

import pytest

from fuzzoff import releases
from tests.helpers import CORPORA, ROOT, run_cli, run_cli_process

# A planted fault (the loss rules off) that the first examples already break.
PLANTED = ["fuzz", "--px4", "1.15", "--vehicle", "mc", "--transport", "ros2", "--seed", "7"]
PLANTED += ["--examples", "300", "--property", "explained", "--ignore", "OFB103,OFB101", "-q"]


def _one_error_line(stderr: str) -> str:
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    return lines[0]


@pytest.mark.parametrize("save_dir", ["afile", "afile/sub"])
def test_a_save_dir_that_cannot_be_made_is_refused_before_the_campaign(
    tmp_path: Path, save_dir: str
) -> None:
    (tmp_path / "afile").write_text("x")
    out = run_cli([*PLANTED, "--save-dir", save_dir], cwd=tmp_path)
    assert out.returncode == 2
    assert "--save-dir" in _one_error_line(out.stderr) and "afile is not a folder" in out.stderr
    assert out.stdout == "", "the campaign did not run"


def test_a_missing_save_dir_is_not_left_behind_when_nothing_is_found(tmp_path: Path) -> None:
    args = ["fuzz", "--examples", "2", "--property", "invariants", "-q"]
    out = run_cli([*args, "--save-dir", "new/deeper"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert not (tmp_path / "new").exists()


def test_a_save_that_fails_after_the_campaign_still_reports_the_counterexample(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def disk_full(*_: object, **__: object) -> Path:
        raise OSError(28, "No space left on device", str(tmp_path / "x.mcap"))

    monkeypatch.setattr("fuzzoff.commands.fuzz.save", disk_full)
    out = run_cli([*PLANTED, "--save-dir", str(tmp_path), "--format", "json"])
    assert out.returncode == 2
    line = _one_error_line(out.stderr)
    assert "No space left on device" in line and "explained counterexample was not saved" in line
    (prop,) = json.loads(out.stdout)["properties"]
    assert prop["failed"] and prop["counterexample"] and prop["reproducer"] is None


@pytest.mark.parametrize("budget", ["nan", "inf"])
def test_a_budget_that_is_not_a_finite_number_is_refused(budget: str) -> None:
    args = ["fuzz", "--budget", budget, "--property", "invariants", "--no-save", "-q"]
    out = run_cli_process(args, timeout=60)  # NaN never ran out: the campaign never stopped
    assert out.returncode == 2
    assert f"--budget {budget}" in _one_error_line(out.stderr)


def test_a_budget_too_small_for_one_example_is_not_all_held() -> None:
    args = ["fuzz", "--budget", "1e-9", "--property", "invariants", "--no-save", "-q"]
    out = run_cli(args)
    assert out.returncode == 2
    assert "ran no example of invariants" in _one_error_line(out.stderr)
    assert "all held" not in out.stdout and "no example of invariants ran" in out.stdout
    data = json.loads(run_cli([*args, "--format", "json"]).stdout)
    assert data["unchecked"] == ["invariants"] and data["properties"][0]["examples"] == 0


def test_from_an_incomplete_recording_fuzzes_the_readable_part_and_exits_2() -> None:
    cut = CORPORA / "mcap" / "truncated.mcap"
    lint = run_cli(["lint", str(cut), "--format", "json"])
    assert lint.returncode == 2
    args = ["fuzz", "--from", str(cut), "--examples", "3", "--property", "invariants"]
    out = run_cli([*args, "--no-save", "-q", "--format", "json"])
    assert out.returncode == 2
    assert _one_error_line(out.stderr) == lint.stderr.strip(), "the reader's line, as lint says it"
    report = json.loads(out.stdout)
    assert report["properties"][0]["examples"] == 3, "the readable part was fuzzed"
    assert report["campaign"]["from_problems"] == [out.stderr.strip().removeprefix("fuzzoff: ")]
    text = run_cli([*args, "--no-save", "-q"]).stdout
    assert "--from incomplete" in text


def test_from_a_folder_of_recordings_is_a_usage_error(tmp_path: Path) -> None:
    for name in ("a.mcap", "b.mcap"):
        (tmp_path / name).write_bytes((CORPORA / "mcap" / "stream_lost.mcap").read_bytes())
    out = run_cli(["fuzz", "--from", str(tmp_path), "--examples", "1", "--no-save", "-q"])
    assert out.returncode == 2
    line = _one_error_line(out.stderr)
    assert str(tmp_path) in line and "not a ROS 2 bag" in line and "one recording" in line


REPRODUCER = CORPORA / "fuzz" / "explained-1.15-mc-ros2-24600598.expected.json"


def _reproducer(tmp_path: Path, change: Callable[[dict[str, Any]], None]) -> Path:
    """A copy of a committed reproducer with one field changed."""
    spec = json.loads(REPRODUCER.read_text())
    shutil.copy(REPRODUCER.parent / spec["recording"], tmp_path)
    change(spec)
    path = tmp_path / REPRODUCER.name
    path.write_text(json.dumps(spec))
    return path


def _set(*keys: str, value: Any) -> Callable[[dict[str, Any]], None]:
    def change(spec: dict[str, Any]) -> None:
        for key in keys[:-1]:
            spec = spec[key]
        spec[keys[-1]] = value

    return change


def _drop_severity(spec: dict[str, Any]) -> None:
    del spec["findings"][0]["severity"]


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (_set("scenario", "params", value={"COM_OF_LOSS_T": "a"}), "scenario.params.COM_OF_LOSS_T"),
        (_set("scenario", "px4", value="foo"), "scenario.px4"),
        (_set("scenario", "vehicle", value="heli"), "scenario.vehicle"),
        (_set("scenario", "transport", value="can"), "scenario.transport"),
        (_set("scenario", "ignore", value=5), "scenario.ignore"),
        (_set("scenario", "ignore", value=["OFB999"]), "scenario.ignore"),
        (_set("scenario", value="x"), "scenario"),
        (_drop_severity, "findings[0]"),
        (_set("findings", value="x"), "findings"),
        (_set("findings", value=[{"code": "OFB101", "severity": "fatal"}]), "findings[0].severity"),
        (_set("property", value="nope"), "property"),
        (_set("cut_fraction", value="half"), "cut_fraction"),
        (_set("recording", value="../../etc/passwd"), "recording"),
        (_set("recording", value="/etc/passwd"), "recording"),
    ],
)
def test_replay_of_a_malformed_reproducer_names_the_file_and_the_field(
    tmp_path: Path, change: Callable[[dict[str, Any]], None], field: str
) -> None:
    path = _reproducer(tmp_path, change)
    out = run_cli(["replay", str(path)])
    assert out.returncode == 2, out.stdout
    assert _one_error_line(out.stderr).startswith(f"error: {path}: {field}: ")


def test_replay_takes_a_full_px4_release_as_the_options_do(tmp_path: Path) -> None:
    path = _reproducer(tmp_path, _set("scenario", "px4", value="1.15.4"))
    out = run_cli(["replay", str(path), "--format", "json"])
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["findings_match"] and not data["property_still_fails"]


TLOG_REPRODUCER = CORPORA / "fuzz" / "explained-1.16-mc-mavlink-480969c1.expected.json"


def test_replay_to_a_host_that_cannot_be_resolved_is_one_line() -> None:
    target = "udp:nonexistent.invalid:14540"  # .invalid never resolves (RFC 6761)
    out = run_cli(["replay", str(TLOG_REPRODUCER), "--to", target])
    assert out.returncode == 2
    assert "cannot resolve host 'nonexistent.invalid'" in _one_error_line(out.stderr)


def test_replay_to_an_ipv6_address_in_brackets_sends_there() -> None:
    """The live client heartbeats to the address while it waits for PX4; nobody answers here,
    so it says so in one line (exit 2) after --connect-timeout."""
    try:
        listener = socket.socket(socket.AF_INET6, socket.SOCK_DGRAM)
        listener.bind(("::1", 0))
    except OSError:
        pytest.skip("no IPv6 loopback here")
    with listener:
        listener.settimeout(5.0)
        port = listener.getsockname()[1]
        target = f"udp:[::1]:{port}"
        args = ["replay", str(TLOG_REPRODUCER), "--to", target, "--connect-timeout", "1"]
        out = run_cli(args)
        assert out.returncode == 2, out.stdout
        assert f"--to [::1]:{port}: no PX4 HEARTBEAT" in _one_error_line(out.stderr)
        assert listener.recv(4096)[:1] in (b"\xfd", b"\xfe"), "a MAVLink packet arrived"


def test_replay_to_an_ipv6_address_without_brackets_says_how_to_write_it() -> None:
    out = run_cli(["replay", str(TLOG_REPRODUCER), "--to", "udp:::1:14540"])
    assert out.returncode == 2
    assert "in brackets" in _one_error_line(out.stderr)


@pytest.mark.parametrize("speed", ["nan", "inf", "1e-300", "0", "-2", "1000"])
def test_replay_speed_outside_its_range_is_a_usage_error(speed: str) -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sink:
        sink.bind(("127.0.0.1", 0))
        target = f"udp:127.0.0.1:{sink.getsockname()[1]}"
        out = run_cli(["replay", str(TLOG_REPRODUCER), "--to", target, "--speed", speed])
    assert out.returncode == 2
    assert f"--speed {speed}: expected 0.01 to 100" in _one_error_line(out.stderr)


def test_fuzz_writes_nothing_into_the_working_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Hypothesis keeps caches (the constants it collects from local source files) in
    ``.hypothesis/`` of the working folder even with its database off. A new process: the
    caches are written once per process, so an in-process run after other tests writes none."""
    monkeypatch.setenv("PYTHONPATH", str(ROOT))  # this checkout's fuzzoff, from any folder
    monkeypatch.delenv("HYPOTHESIS_STORAGE_DIRECTORY", raising=False)
    args = ["fuzz", "--examples", "3", "--property", "invariants", "--no-save", "-q"]
    out = run_cli_process(args, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_fuzz_sarif_locates_a_reproducer_with_a_percent_encoded_uri_as_lint_does(
    tmp_path: Path,
) -> None:
    out = run_cli([*PLANTED, "--save-dir", "saved é x", "--format", "sarif"], cwd=tmp_path)
    assert out.returncode == 1, out.stderr
    (run,) = json.loads(out.stdout)["runs"]
    (result,) = run["results"]
    location = result["locations"][0]["physicalLocation"]["artifactLocation"]
    assert location["uriBaseId"] == "SRCROOT"
    assert location["uri"].startswith("saved%20%C3%A9%20x/explained-")
    assert run["originalUriBaseIds"]["SRCROOT"]["uri"] == tmp_path.resolve().as_uri() + "/"
    assert (tmp_path / unquote(location["uri"])).is_file()


@pytest.mark.parametrize("content", [b"", b"%PDF-1.4 not a recording\n" * 40])
def test_replay_of_a_reproducer_whose_recording_is_not_readable_is_one_line(
    tmp_path: Path, content: bytes
) -> None:
    path = _reproducer(tmp_path, lambda spec: None)
    recording = tmp_path / json.loads(path.read_text())["recording"]
    recording.write_bytes(content)
    out = run_cli(["replay", str(path)])
    assert out.returncode == 2
    assert _one_error_line(out.stderr).startswith(f"fuzzoff: {recording}: ")


_PAST = f"1.{releases.newest_listed()[1] + 1}"
"""The release after the newest modelled one."""


@pytest.mark.parametrize(
    ("px4", "said"),
    [
        ("2.0", "PX4 2.0 is not modelled"),
        (_PAST, f"PX4 {_PAST} is not modelled"),
        ("1.4", "oldest"),
    ],
)
def test_a_px4_release_not_modelled_is_refused_as_lint_refuses_it(
    tmp_path: Path, px4: str, said: str
) -> None:
    out = run_cli(["fuzz", "--px4", px4, "--examples", "1"], cwd=tmp_path)
    assert out.returncode == 2 and out.stdout == "", "the campaign did not run"
    line = _one_error_line(out.stderr)
    assert "--px4" in line and said in line
