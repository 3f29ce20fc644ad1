"""``fuzzoff fuzz`` for people who use it: fuzzoff's own known problems do not fail their
campaign, nothing is written into their folder unless a counterexample is saved (and then under
``.fuzzoff/reproducers/``), ``--examples N`` runs N examples, and ``--from`` names the outcome that
flips; the README's example runs as shown."""

from __future__ import annotations

import contextlib
import io
import json
import re
import shlex
from pathlib import Path

import pytest

from fuzzoff.cli import main
from fuzzoff.fuzz.known import KNOWN
from tests.helpers import ROOT, run_cli, run_cli_process

# PX4 1.11 over MAVLink: fuzzoff's known problem (the GLOBAL_INT handler) in the first examples.
KNOWN_PROBLEM = ["fuzz", "--px4", "1.11", "--transport", "mavlink", "--seed", "3"]
KNOWN_PROBLEM += ["--examples", "20", "--property", "explained", "-q", "--no-save"]

# A planted fault (the loss rules off) that early examples already break.
PLANTED = ["fuzz", "--px4", "1.15", "--vehicle", "mc", "--transport", "ros2", "--seed", "7"]
PLANTED += ["--property", "explained", "--ignore", "OFB103,OFB101", "-q"]


# As a user runs it, in a process of its own: in this process Hypothesis's state left by earlier
# tests can change which streams a seed draws.
def test_fuzzoffs_own_known_problems_do_not_fail_a_users_campaign() -> None:
    out = run_cli_process(KNOWN_PROBLEM)
    assert out.returncode == 0, out.stdout
    assert "held" in out.stdout
    assert "left out: a known problem of fuzzoff in" in out.stdout
    assert "--include-known" in out.stdout


def test_include_known_fails_on_them_for_fuzzoffs_developers() -> None:
    out = run_cli_process([*KNOWN_PROBLEM, "--include-known", "--format", "json"])
    assert out.returncode == 1
    (prop,) = json.loads(out.stdout)["properties"]
    assert prop["failed"] and prop["known"] == {}
    assert any(re.search(k, p) for k in KNOWN for p in prop["problems"])


def test_a_campaign_that_finds_nothing_writes_nothing(tmp_path: Path) -> None:
    out = run_cli(["fuzz", "--examples", "3", "--property", "invariants", "-q"], cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_counterexample_is_saved_under_fuzzoff_reproducers_not_corpora(tmp_path: Path) -> None:
    out = run_cli([*PLANTED, "--examples", "30"], cwd=tmp_path)
    assert out.returncode == 1, out.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [".fuzzoff"]
    (spec,) = (tmp_path / ".fuzzoff" / "reproducers").glob("*.expected.json")
    assert f"reproducer: .fuzzoff/reproducers/{spec.name}" in out.stdout
    replay = run_cli(["replay", str(spec)])
    assert replay.returncode == 1 and "property explained: still fails" in replay.stdout


def test_an_unwritable_default_folder_says_how_to_choose_another(tmp_path: Path) -> None:
    (tmp_path / ".fuzzoff").write_text("not a folder")
    out = run_cli([*PLANTED, "--examples", "5"], cwd=tmp_path)
    assert out.returncode == 2 and out.stdout == ""
    assert "--save-dir DIR or --no-save" in out.stderr and "Traceback" not in out.stderr


def test_examples_n_runs_n_examples_even_when_one_fails() -> None:
    """The search goes on after a counterexample: every example asked is checked, and the
    shrinking of the first one is counted apart."""
    out = run_cli([*PLANTED, "--examples", "60", "--no-save", "--format", "json"])
    assert out.returncode == 1
    (prop,) = json.loads(out.stdout)["properties"]
    assert prop["examples"] == 60
    assert 1 <= prop["failed_examples"] <= 60
    assert prop["found_after_examples"] <= 60 and prop["shrink_steps"] >= 0
    text = run_cli([*PLANTED, "--examples", "60", "--no-save"]).stdout
    assert f"{prop['failed_examples']} of 60 examples failed; the first" in text


def test_from_names_the_outcome_that_flips() -> None:
    recording = ROOT / "corpora" / "tlog" / "stream_lost_in_offboard.tlog"
    args = ["fuzz", "--from", str(recording), "--examples", "3", "--property", "invariants"]
    out = run_cli([*args, "-q", "--no-save", "--format", "json"])
    assert out.returncode == 0, out.stderr
    margins = {m["family"]: m for m in json.loads(out.stdout)["margins"]}
    # a new gap over COM_OF_LOSS_T and the 10 Hz check window (its phase not in the tlog)
    assert margins["stall"]["changes"] == ["PX4 1.15 runs POSCTL at 5.9 s (offboard loss)"]
    assert margins["drop"]["changes"] == [
        "PX4 1.15 runs POSCTL at 8.8 s (offboard loss), not at 9.1 s"
    ]


_SECONDS = re.compile(r"\d+\.\d+ s( +\d+/s)?")


def _readme_block(name: str) -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = text.split(f"<!-- {name}:start -->", 1)[1].split(f"<!-- {name}:end -->", 1)[0]
    return block.split("```console\n", 1)[1].split("```", 1)[0].splitlines()


def test_the_readme_fuzz_example_runs_as_shown() -> None:
    """Each ``$ fuzzoff ...`` line of the README's fuzz example, run in the project folder,
    prints what follows it (times and rates aside), and ``$ echo $?`` is its exit status."""
    lines = _readme_block("fuzz-from")
    status = None
    i = 0
    while i < len(lines):
        command = lines[i]
        assert command.startswith("$ "), command
        shown = []
        i += 1
        while i < len(lines) and not lines[i].startswith("$ "):
            shown.append(lines[i])
            i += 1
        if command == "$ echo $?":
            assert shown == [str(status)]
            continue
        words = shlex.split(command[2:])
        assert words[0] == "fuzzoff"
        out = run_cli(words[1:], cwd=ROOT)
        status = out.returncode
        got = [_SECONDS.sub("S", line) for line in out.stdout.splitlines()]
        assert got == [_SECONDS.sub("S", line) for line in shown], out.stdout


@pytest.mark.parametrize("command", ["fuzz", "gate", "replay"])
def test_help_says_what_the_exit_status_means(command: str) -> None:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as done:
        main([command, "--help"])
    assert done.value.code == 0
    text = " ".join(out.getvalue().split())
    assert "exit status" in text and "0 " in text and ", 1 " in text and ", 2 " in text


def test_the_command_judges_each_written_recording_with_its_scenarios_profile() -> None:
    """A command-line run looks up each recording's nearest configuration; the campaign's
    recordings are its own temporary files, judged with their scenario's PX4 profile. Looked
    up, a legacy MAVLink stream's tlog was judged as PX4 1.15, and the round trip failed on
    most examples (seed 7: 70 of 88)."""
    args = ["fuzz", "--examples", "12", "--seed", "7", "--no-save", "-q", "--format", "json"]
    out = run_cli([*args, "--property", "round-trip", "--property", "truncation"])
    assert out.returncode == 0, out.stdout


def test_a_reproducer_keeps_the_rule_settings_of_the_campaigns_configuration(
    tmp_path: Path,
) -> None:
    """The working folder's configuration lowers the loss rules to info, so a loss is left
    unexplained: the reproducer keeps those severities, and its replay from another folder
    checks the property with them (without them it said fixed)."""
    (tmp_path / "fuzzoff.toml").write_text('severity = { OFB103 = "info", OFB101 = "info" }\n')
    args = ["fuzz", "--px4", "1.15", "--vehicle", "mc", "--transport", "ros2", "--seed", "7"]
    out = run_cli([*args, "--examples", "30", "--property", "explained", "-q"], cwd=tmp_path)
    assert out.returncode == 1, out.stdout
    (spec_path,) = (tmp_path / ".fuzzoff" / "reproducers").glob("*.expected.json")
    spec = json.loads(spec_path.read_text())
    assert spec["scenario"]["severity"] == {"OFB101": "info", "OFB103": "info"}
    replay = run_cli(["replay", str(spec_path)], cwd=ROOT)
    assert replay.returncode == 1 and "property explained: still fails" in replay.stdout
