"""Which recordings ``fuzzoff lint PATH...`` finds: each once, never a pipe, never nothing."""

from __future__ import annotations

import json
import os
import shutil
import sys
from pathlib import Path

import pytest

from tests.helpers import CORPORA, run_cli, run_cli_process

GOOD = CORPORA / "tlog" / "good_offboard.tlog"
GAP = CORPORA / "tlog" / "stream_lost_in_offboard.tlog"  # findings at the default fail level


def _linted(*args: str | Path) -> list[str]:
    result = run_cli(["lint", *map(str, args), "--format", "json", "--no-progress"])
    assert result.returncode in (0, 1), result.stderr
    return [f["path"] for f in json.loads(result.stdout)["files"]]


def test_a_link_back_up_the_tree_lists_each_recording_once(tmp_path: Path) -> None:
    shutil.copy(GOOD, tmp_path / "flight.tlog")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "up").symlink_to("..")
    assert _linted(tmp_path) == [str(tmp_path / "flight.tlog")]


def test_a_linked_folder_is_searched_once_under_its_first_name(tmp_path: Path) -> None:
    day = tmp_path / "2026-11-22"
    day.mkdir()
    shutil.copy(GOOD, day / "a.tlog")
    shutil.copy(GAP, day / "b.tlog")
    (tmp_path / "latest").symlink_to(day.name)
    assert _linted(tmp_path) == [str(day / "a.tlog"), str(day / "b.tlog")]


def test_a_linked_folder_given_alone_is_searched(tmp_path: Path) -> None:
    day = tmp_path / "2026-11-22"
    day.mkdir()
    shutil.copy(GOOD, day / "a.tlog")
    (tmp_path / "latest").symlink_to(day.name)
    assert _linted(tmp_path / "latest") == [str(tmp_path / "latest" / "a.tlog")]


def test_a_recording_named_twice_is_linted_once(tmp_path: Path) -> None:
    shutil.copy(GOOD, tmp_path / "a.tlog")
    a = tmp_path / "a.tlog"
    assert _linted(tmp_path, a, a) == [str(a)]


def test_upper_case_suffixes_are_found(tmp_path: Path) -> None:
    """Logs copied off an SD card or a Windows ground station: ``LOG001.ULG``, ``FLIGHT.TLOG``."""
    shutil.copy(GOOD, tmp_path / "FLIGHT.TLOG")
    shutil.copy(GAP, tmp_path / "b.Tlog")
    assert _linted(tmp_path) == [str(tmp_path / "FLIGHT.TLOG"), str(tmp_path / "b.Tlog")]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_a_pipe_in_a_searched_folder_is_left_out_and_the_lint_finishes(tmp_path: Path) -> None:
    shutil.copy(GOOD, tmp_path / "a.tlog")
    os.mkfifo(tmp_path / "live.tlog")  # nobody writes to it: opening it would wait forever
    result = run_cli_process(["lint", str(tmp_path), "--format", "json"], timeout=120)
    assert result.returncode == 0, result.stderr
    assert [f["path"] for f in json.loads(result.stdout)["files"]] == [str(tmp_path / "a.tlog")]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_a_pipe_named_on_the_command_line_is_one_clear_line(tmp_path: Path) -> None:
    pipe = tmp_path / "live.tlog"
    os.mkfifo(pipe)
    result = run_cli_process(["lint", str(pipe)], timeout=120)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        f"fuzzoff: {pipe}: a pipe, not a file: fuzzoff reads recordings from files "
        "(save a stream to one first)"
    ]


@pytest.mark.parametrize("content", [[], ["notes.txt", "plot.png"]])
def test_a_folder_without_recordings_is_a_usage_error(tmp_path: Path, content: list[str]) -> None:
    for name in content:
        (tmp_path / name).write_text("not a flight")
    result = run_cli(["lint", str(tmp_path)])
    assert result.returncode == 2
    assert f"no recordings in {tmp_path}" in result.stderr
    assert ".tlog" in result.stderr and "Traceback" not in result.stderr


@pytest.mark.parametrize("fmt", ["json", "sarif", "junit", "html", "terminal"])
def test_a_name_that_is_not_utf8_is_written_in_every_report(tmp_path: Path, fmt: str) -> None:
    """A byte that is not UTF-8 in a file's name shows as ``\\xNN``: the report stays valid
    UTF-8, instead of failing to be written at all."""
    name = os.fsdecode(b"flight-\xff-\x1b[31m.tlog")
    shutil.copy(GAP, tmp_path / name)
    out = tmp_path / f"report.{fmt}"
    result = run_cli(["lint", str(tmp_path), "--format", fmt, "--output", str(out)])
    assert result.returncode == 1, result.stderr
    text = out.read_bytes().decode("utf-8")  # strict: the report is UTF-8
    assert "flight-" in text and "\ufffd" not in text
    if fmt == "json":
        (linted,) = json.loads(text)["files"]
        assert linted["path"] == str(tmp_path / "flight-\\xff-\x1b[31m.tlog")


def test_a_folder_tree_deeper_than_pythons_recursion_limit_is_searched(tmp_path: Path) -> None:
    folders = [tmp_path / "d"]
    for _ in range(sys.getrecursionlimit() + 100):
        folders.append(folders[-1] / "d")
    try:
        for folder in folders:
            folder.mkdir()
        shutil.copy(GOOD, folders[-1] / "a.tlog")
        assert _linted(tmp_path) == [str(folders[-1] / "a.tlog")]
    finally:  # deepest first: shutil.rmtree (pytest's clean-up too) recurses per level
        (folders[-1] / "a.tlog").unlink(missing_ok=True)
        for folder in reversed(folders):
            if folder.exists():
                folder.rmdir()


def test_a_fleet_lint_finds_the_recordings_as_a_plain_lint(tmp_path: Path) -> None:
    """One search for both paths: a recording named twice, under a link and in a folder named
    too, is linted once, where first named, whether or not the lint writes the Parquet dataset."""
    pytest.importorskip("pyarrow")
    folder = tmp_path / "flights"
    folder.mkdir()
    shutil.copy(GOOD, folder / "a.tlog")
    shutil.copy(GAP, folder / "b.tlog")
    (folder / "c.tlog").symlink_to("b.tlog")
    named = [folder / "b.tlog", folder, folder / "c.tlog"]
    plain = _linted(*named)
    report = tmp_path / "fleet.json"
    dataset = ["--format", "parquet", "-o", str(tmp_path / "dataset")]
    json_report = ["--format", "json", "-o", str(report)]
    result = run_cli(["lint", *map(str, named), "--no-progress", *json_report, *dataset])
    assert result.returncode in (0, 1), result.stderr
    fleet = [f["path"] for f in json.loads(report.read_text())["files"]]
    assert plain == fleet == [str(folder / "b.tlog"), str(folder / "a.tlog")]
