"""The repository's GitHub Action (``action.yml``) and workflows: actionlint passes them (and
refuses an input the action lacks), every input reaches a step, and the lint step run as a
runner runs it writes the reports it promises, keeps the status for the last step and lets a
user's inputs through."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

from tests.action_runner import ACTION, ACTIONLINT, actionlint, run_step
from tests.helpers import CORPORA, ROOT

WORKFLOWS = sorted((ROOT / ".github" / "workflows").glob("*.yml"))

USING_THE_ACTION = """
name: t
on: push
permissions:
  contents: read
  security-events: write
jobs:
  lint:
    runs-on: ubuntu-latest
    steps:
      - uses: actions/checkout@v4
      - uses: ./
        with:
          {key}: logs/
"""


def test_the_repositorys_workflows_pass_actionlint() -> None:
    assert WORKFLOWS, "no workflow in .github/workflows"
    proc = subprocess.run(
        [str(ACTIONLINT), "-no-color", *map(str, WORKFLOWS)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_actionlint_checks_a_workflow_against_the_actions_inputs(tmp_path: Path) -> None:
    good = actionlint(USING_THE_ACTION.format(key="paths"), tmp_path / "good")
    assert good.returncode == 0, good.stdout
    bad = actionlint(USING_THE_ACTION.format(key="path"), tmp_path / "bad")
    assert bad.returncode == 1 and 'input "path" is not defined' in bad.stdout


def test_every_input_reaches_a_step() -> None:
    text = json.dumps(ACTION["runs"]["steps"])
    for name in ACTION["inputs"]:
        assert f"inputs.{name}" in text, f"input {name} is used by no step"


def _logs(tmp_path: Path, *names: str) -> Path:
    logs = tmp_path / "logs"
    logs.mkdir()
    for name in names:
        shutil.copy(CORPORA / "tlog" / name, logs / name)
    return logs


def test_the_lint_step_writes_both_reports_and_keeps_the_status(tmp_path: Path) -> None:
    _logs(tmp_path, "stream_lost_in_offboard.tlog", "good_offboard.tlog")
    run = run_step("lint", {"paths": "logs/"}, tmp_path, tmp_path)
    assert run.returncode == 0, run.stderr  # the step passes: the last step fails the job
    assert run.outputs["status"] == "1"
    sarif = json.loads(Path(run.outputs["sarif-file"]).read_text(encoding="utf-8"))
    assert sarif["version"] == "2.1.0" and sarif["runs"][0]["results"]
    html = Path(run.outputs["html-file"]).read_text(encoding="utf-8")
    assert "stream_lost_in_offboard.tlog" in html and "<!DOCTYPE html>" in html[:200]
    assert "OFB101" in run.stdout  # the findings in the job's log
    fail = ACTION["runs"]["steps"][-1]
    assert fail["if"] == "${{ steps.lint.outputs.status != '0' }}"


def test_the_inputs_reach_the_lint(tmp_path: Path) -> None:
    _logs(tmp_path, "stream_lost_in_offboard.tlog")
    given = {
        "paths": "logs/stream_lost_in_offboard.tlog",
        "px4": "1.16",
        "fail-on": "error",
        "args": "--select OFB3",
        "sarif": "false",
        "html": "false",
    }
    run = run_step("lint", given, tmp_path, tmp_path)
    assert run.outputs["status"] == "0", run.stdout + run.stderr
    assert "PX4 1.16" in run.stdout and "OFB101" not in run.stdout
    assert "sarif-file" not in run.outputs and "html-file" not in run.outputs


def test_a_recording_it_cannot_read_gives_status_2(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "flight.tlog").write_bytes(b"\xfe\x09" + b"not a tlog" * 3)
    run = run_step(
        "lint", {"paths": "logs/", "sarif": "false", "html": "false"}, tmp_path, tmp_path
    )
    assert run.returncode == 0 and run.outputs["status"] == "2"
    assert "flight.tlog" in run.stderr


def test_annotations_and_a_baseline(tmp_path: Path) -> None:
    """Each finding printed as a workflow command; a baseline's findings fail nothing."""
    _logs(tmp_path, "stream_lost_in_offboard.tlog")
    off = {"paths": "logs/", "sarif": "false", "html": "false"}
    run = run_step("lint", off, tmp_path, tmp_path)
    assert run.outputs["status"] == "1"
    commands = [line for line in run.stdout.splitlines() if line.startswith("::")]
    assert any(
        line.startswith("::error file=logs/stream_lost_in_offboard.tlog,") for line in commands
    )
    subprocess.run(
        [sys.executable, "-m", "fuzzoff.cli", "lint", "logs/", "--write-baseline", "base.json"],
        cwd=tmp_path,
        capture_output=True,
        check=True,
    )
    again = run_step("lint", {**off, "baseline": "base.json"}, tmp_path, tmp_path)
    assert again.outputs["status"] == "0", again.stdout + again.stderr
    assert not [line for line in again.stdout.splitlines() if line.startswith("::")]
    quiet = run_step("lint", {**off, "annotations": "false"}, tmp_path, tmp_path)
    assert not [line for line in quiet.stdout.splitlines() if line.startswith("::")]
