"""Run the repository's GitHub Action (``action.yml``) the way a runner does, for the tests: its
lint step's script under bash with the environment GitHub gives it (the step's ``env`` from the
inputs, ``GITHUB_OUTPUT``, ``RUNNER_TEMP``), and ``actionlint`` on workflows that use it."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML

from tests.helpers import ROOT

ACTION: dict[str, Any] = YAML(typ="safe").load((ROOT / "action.yml").read_text(encoding="utf-8"))
INPUT = re.compile(r"^\$\{\{ inputs\.(?P<name>[\w-]+) \}\}$")
ACTIONLINT = Path(sys.executable).with_name("actionlint")


@dataclass
class StepRun:
    returncode: int
    stdout: str
    stderr: str
    outputs: dict[str, str]


def step(step_id: str) -> dict[str, Any]:
    return next(s for s in ACTION["runs"]["steps"] if s.get("id") == step_id)


def inputs_with(given: dict[str, str]) -> dict[str, str]:
    """The inputs as the runner resolves them: what the workflow gives, else the default."""
    unknown = set(given) - set(ACTION["inputs"])
    assert not unknown, f"not inputs of action.yml: {sorted(unknown)}"
    return {
        name: str(given.get(name, spec.get("default", "")))
        for name, spec in ACTION["inputs"].items()
    }


def run_step(step_id: str, given: dict[str, str], cwd: Path, runner_temp: Path) -> StepRun:
    """One ``shell: bash`` step of the action, its ``env`` made from the inputs (only plain
    ``${{ inputs.NAME }}`` references are allowed there: anything else would need a runner),
    with fuzzoff from this test environment on the PATH as the install step puts it there."""
    spec = step(step_id)
    assert spec["shell"] == "bash"
    values = inputs_with(given)
    env = {**os.environ, "NO_COLOR": "1"}
    for key, expression in spec.get("env", {}).items():
        match = INPUT.match(str(expression))
        assert match, f"{step_id}: env {key} is not a plain input reference: {expression}"
        env[key] = values[match.group("name")]
    outputs = runner_temp / "github_output"
    outputs.write_text("")
    env |= {
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{env['PATH']}",
        "GITHUB_OUTPUT": str(outputs),
        "RUNNER_TEMP": str(runner_temp),
    }
    # GitHub runs `shell: bash` steps as `bash --noprofile --norc -eo pipefail {0}`.
    proc = subprocess.run(
        ["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c", spec["run"]],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    pairs = (line.partition("=") for line in outputs.read_text().splitlines() if line)
    return StepRun(proc.returncode, proc.stdout, proc.stderr, {k: v for k, _, v in pairs})


def actionlint(workflow: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    """actionlint on one workflow in a scratch repository beside a copy of ``action.yml``, so
    that ``uses: ./`` is checked against the action's real inputs."""
    repo = tmp_path / "repo"
    (repo / ".github" / "workflows").mkdir(parents=True)
    (repo / ".git").mkdir()  # actionlint finds a local action from the repository's root
    shutil.copy(ROOT / "action.yml", repo / "action.yml")
    (repo / ".github" / "workflows" / "workflow.yml").write_text(workflow, encoding="utf-8")
    return subprocess.run(
        [str(ACTIONLINT), "-no-color", ".github/workflows/workflow.yml"],
        cwd=repo,
        capture_output=True,
        text=True,
        timeout=120,
    )
