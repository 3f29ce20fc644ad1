"""The README is the package page: every command block it shows is run here, as a user would.

``console`` blocks: each ``$ fuzzoff ...`` line runs from the repository root in a 120-column,
colourless environment, and the lines shown under it must appear in its output, in order
(``...`` stands for lines left out); ``$ echo $?`` shows the previous command's exit status. A
block without a language is a line from an output shown above it. The ``toml`` configuration is
used for a lint, the ``python`` API example runs against corpus recordings, the GitHub Actions
workflow's lint step runs in a folder of recordings and writes the two reports its upload steps
name (the repository's action, run as a runner does, its inputs checked by actionlint), and the
pre-commit configuration is the repository's own hook. A block marked
``<!-- readme-test: not run (why) -->`` is left out, and says why.
"""

from __future__ import annotations

import json
import re
import shutil
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest
from ruamel.yaml import YAML

from tests.action_runner import actionlint, run_step
from tests.helpers import CORPORA, ROOT, run_cli

README = (ROOT / "README.md").read_text(encoding="utf-8")
FENCE = re.compile(r"^(?P<fence>`{3,})(?P<lang>[\w-]*)\n(?P<body>.*?)^(?P=fence)$", re.M | re.S)
NOT_RUN = re.compile(r"<!-- readme-test: not run \((?P<why>[^)]+)\) -->\s*$")
DURATION = re.compile(r"\d+\.\d+ s( +\d+/s)?")


@dataclass(frozen=True)
class Block:
    lang: str
    body: str
    line: int
    skipped: str | None

    @property
    def name(self) -> str:
        return f"{self.lang or 'plain'}@{self.line}"


def _blocks() -> list[Block]:
    out = []
    for match in FENCE.finditer(README):
        before = README[: match.start()].rstrip("\n").rsplit("\n", 1)[-1]
        skipped = NOT_RUN.search(before)
        out.append(
            Block(
                match.group("lang"),
                match.group("body"),
                README.count("\n", 0, match.start()) + 1,
                skipped.group("why") if skipped else None,
            )
        )
    return out


BLOCKS = _blocks()


def _of(lang: str) -> list[Block]:
    return [b for b in BLOCKS if b.lang == lang and b.skipped is None]


def test_every_block_is_run_here_or_says_why_not() -> None:
    handled = {"console", "", "toml", "python", "yaml"}
    for block in BLOCKS:
        assert block.skipped is not None or block.lang in handled, block.name
    assert [b.lang for b in BLOCKS if b.skipped] == ["sh"]  # the install commands
    assert len(_of("console")) >= 3 and _of("yaml") and _of("toml") and _of("python")


@dataclass
class Command:
    argv: list[str]
    shown: list[str]


def _commands(body: str) -> list[Command]:
    commands: list[Command] = []
    for line in body.splitlines():
        if line.startswith("$ "):
            commands.append(Command(line[2:].split(), []))
        else:
            commands[-1].shown.append(line.rstrip())
    return commands


def _in_order(shown: list[str], actual: list[str]) -> None:
    """Each run of shown lines between ``...`` appears in ``actual``, consecutively and in
    order; a block that does not start (end) with ``...`` starts (ends) the output."""
    groups: list[list[str]] = [[]]
    for line in shown:
        if line == "...":
            groups.append([])
        else:
            groups[-1].append(line)
    at = 0
    for i, group in enumerate(groups):
        if not group:
            continue
        n = len(group)
        starts = [j for j in range(at, len(actual) - n + 1) if actual[j : j + n] == group]
        assert starts, f"not in the output (from line {at}):\n" + "\n".join(group)
        if i == 0 and shown[0] != "...":
            assert starts[0] == 0, f"the output does not start with {group[0]!r}"
        at = starts[0] + n
    if shown and shown[-1] != "...":
        assert at == len(actual), f"the output goes on after {shown[-1]!r}"


@pytest.fixture
def terminal_of_120_columns(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "120")
    monkeypatch.setenv("NO_COLOR", "1")
    monkeypatch.delenv("FORCE_COLOR", raising=False)


CONSOLE = _of("console")


@pytest.mark.parametrize("block", CONSOLE, ids=[b.name for b in CONSOLE])
def test_console_block_prints_what_the_readme_shows(
    block: Block, terminal_of_120_columns: None
) -> None:
    status = None
    for command in _commands(block.body):
        if command.argv == ["echo", "$?"]:
            assert command.shown == [str(status)]
            continue
        assert command.argv[0] == "fuzzoff", command.argv
        result = run_cli(command.argv[1:], cwd=ROOT)
        status = result.returncode
        assert status in (0, 1), result.stderr
        actual = [ln.rstrip() for ln in result.stdout.splitlines()]
        shown = command.shown
        if command.argv[1] == "fuzz":  # a campaign's durations and rates vary from run to run
            actual = [DURATION.sub("S", ln) for ln in actual]
            shown = [DURATION.sub("S", ln) for ln in shown]
        _in_order(shown, actual)


def _outputs() -> list[str]:
    lines = []
    for block in CONSOLE:
        for command in _commands(block.body):
            lines += command.shown
    return lines


@pytest.mark.parametrize("block", _of(""), ids=[b.name for b in _of("")])
def test_a_plain_block_is_a_line_the_readme_shows_in_an_output(block: Block) -> None:
    outputs = _outputs()
    for line in block.body.splitlines():
        assert line.rstrip() in outputs, line


def test_the_configuration_example_configures_a_lint(tmp_path: Path) -> None:
    (block,) = _of("toml")
    config = tomllib.loads(block.body)["tool"]["fuzzoff"]
    (tmp_path / "pyproject.toml").write_text(block.body, encoding="utf-8")
    shutil.copy(CORPORA / "tlog" / "stream_lost_in_offboard.tlog", tmp_path / "flight.tlog")
    result = run_cli(["lint", "flight.tlog", "--format", "json"], cwd=tmp_path)
    assert result.returncode in (0, 1), result.stderr
    findings = json.loads(result.stdout)["files"][0]["findings"]
    assert findings and all(f["code"][:4] in ("OFB1", "OFB2") for f in findings)
    assert not any(f["code"] in config["ignore"] for f in findings)
    assert json.loads(result.stdout)["files"][0]["profile"]["px4"] == config["px4"]


def test_the_python_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (block,) = _of("python")
    shutil.copy(CORPORA / "tlog" / "stream_lost_in_offboard.tlog", tmp_path / "flight.tlog")
    (tmp_path / "logs").mkdir()
    shutil.copy(CORPORA / "tlog" / "good_offboard.tlog", tmp_path / "logs" / "good.tlog")
    monkeypatch.chdir(tmp_path)
    scope: dict[str, object] = {}
    exec(compile(block.body, "README.md", "exec"), scope)
    findings = scope["findings"]
    assert isinstance(findings, list) and any(f.code == "OFB303" for f in findings)


def _yaml(block: Block) -> object:
    return YAML(typ="safe").load(block.body)


def _workflow() -> dict[str, object]:
    for block in _of("yaml"):
        data = _yaml(block)
        if isinstance(data, dict) and "jobs" in data:
            return data
    raise AssertionError("no GitHub Actions workflow in the README")


def test_the_github_workflow_uses_the_action_with_inputs_it_has(tmp_path: Path) -> None:
    """The README's workflow names the repository's action; actionlint checks its inputs
    against action.yml (with the action as ``./``), and its lint step, run with those inputs on
    a folder of recordings, writes both reports and keeps the status for the job's last step."""
    workflow = _workflow()
    assert workflow["permissions"] == {"contents": "read", "security-events": "write"}
    jobs = workflow["jobs"]
    assert isinstance(jobs, dict)
    steps = next(iter(jobs.values()))["steps"]
    (action,) = (s for s in steps if str(s.get("uses", "")).startswith("fuzzoff/fuzzoff@"))
    text = next(b.body for b in _of("yaml") if "jobs:" in b.body)
    linted = actionlint(text.replace(action["uses"], "./"), tmp_path)
    assert linted.returncode == 0, linted.stdout
    logs = tmp_path / "logs"
    logs.mkdir()
    for name in ("stream_lost_in_offboard.tlog", "good_offboard.tlog"):
        shutil.copy(CORPORA / "tlog" / name, logs / name)
    run = run_step("lint", action["with"], tmp_path, tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.outputs["status"] == "1"  # the action's last step fails the job with it
    assert json.loads(Path(run.outputs["sarif-file"]).read_text())["runs"][0]["results"]
    assert "stream_lost_in_offboard.tlog" in Path(run.outputs["html-file"]).read_text()


def test_the_pre_commit_example_is_the_repositorys_hook() -> None:
    (hook,) = YAML(typ="safe").load((ROOT / ".pre-commit-hooks.yaml").read_text())
    configs = [_yaml(b) for b in _of("yaml")]
    config = next(c for c in configs if isinstance(c, dict) and "repos" in c)
    (repo,) = config["repos"]
    assert repo["repo"].endswith("/fuzzoff") and repo["rev"].startswith("v")
    assert repo["hooks"] == [{"id": hook["id"]}]


def test_the_precision_table_is_what_the_corpus_gives() -> None:
    """The README's precision table is today's: the corpus's expected findings (replayed by
    the corpus tests) and the gate model against every recorded SITL run."""
    sys.path.insert(0, str(ROOT / "corpora"))
    try:
        import precision
    finally:
        sys.path.remove(str(ROOT / "corpora"))
    marker = "<!-- precision table:"
    start = README.index("\n", README.index(marker)) + 1
    shown = README[start : README.index("\n\n", README.index("| the gate model", start))] + "\n"
    assert shown == precision.table()
