"""Configuration as a user writes it: select/ignore by prefix, severities, thresholds, params."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fuzzoff.config import ConfigError, load_settings
from fuzzoff.findings import Severity
from tests.helpers import CORPORA, run_cli

GAP = CORPORA / "tlog" / "keepalive_gap_0_7s.tlog"


def codes_of(result_stdout: str) -> list[str]:
    return [f["code"] for f in json.loads(result_stdout)["files"][0]["findings"]]


def test_prefix_select_and_ignore(tmp_path: Path) -> None:
    (tmp_path / "fuzzoff.toml").write_text('select = ["OFB1"]\nignore = ["OFB105"]\n')
    settings = load_settings(tmp_path)
    assert "OFB101" in settings.select and "OFB201" not in settings.select
    assert settings.enabled("OFB103") and not settings.enabled("OFB105")


def test_extend_select_adds_to_the_selection(tmp_path: Path) -> None:
    (tmp_path / "fuzzoff.toml").write_text('select = ["OFB1"]\nextend-select = ["OFB201"]\n')
    settings = load_settings(tmp_path)
    assert settings.enabled("OFB201") and settings.enabled("OFB101")
    assert not settings.enabled("OFB301")


def test_fuzzoff_toml_wins_over_a_pyproject_further_up(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text('[tool.fuzzoff]\npx4 = "1.13"\n')
    inner = tmp_path / "flights"
    inner.mkdir()
    (inner / "fuzzoff.toml").write_text('px4 = "1.16"\n')
    assert load_settings(inner).px4 == "1.16"
    assert load_settings(tmp_path).px4 == "1.13"


@pytest.mark.parametrize(
    ("text", "complaint"),
    [
        ('select = ["OFB9"]', "OFB9"),
        ('severity = { OFB101 = "fatal" }', "fatal"),
        ("options = { OFB104 = { stale = 0.3 } }", "stale"),
        ("options = { OFB999 = { stale_s = 0.3 } }", "OFB999"),
        ('options = { OFB104 = { stale_s = "soon" } }', "number"),
        ('params = { COM_OF_LOSS_T = "fast" }', "number"),
        ("params = { COM_OF_LOSS_T = nan }", "finite"),
        ('vehicle = "submarine"', "submarine"),
        ('severity = "error"', "severity must be a table"),
        ("options = 3", "options must be a table"),
        ("options = { OFB104 = 0.3 }", "options.OFB104 must be a table"),
        ("params = [1]", "params must be a table"),
        ("px4 = 1.10", 'px4 must be text in quotes, e.g. px4 = "1.15"'),
        ("vehicle = 3", "vehicle must be text"),
        ("fail-on = 2", "fail-on must be text"),
        ("options = { OFB101 = { max_gap_s = nan } }", "must be a finite number, 0 or more"),
        ("options = { OFB101 = { max_gap_s = -1 } }", "must be a finite number, 0 or more"),
        ("options = { OFB105 = { min_intervals = 2.5 } }", "must be a whole number"),
        ("params = { COM_OF_LOS_T = 0.3 }", "did you mean COM_OF_LOSS_T?"),
        ("select = []", "select names no rule"),
    ],
)
def test_mistakes_are_usage_errors_naming_what_is_wrong(
    tmp_path: Path, text: str, complaint: str
) -> None:
    (tmp_path / "fuzzoff.toml").write_text(text + "\n")
    with pytest.raises(ConfigError, match=complaint):
        load_settings(tmp_path)
    result = run_cli(["lint", str(GAP)], cwd=tmp_path)
    assert result.returncode == 2 and complaint in result.stderr
    assert result.stderr.count("fuzzoff.toml") == 1  # the file is named once, not per layer


def test_severity_override_changes_the_finding_and_the_exit_status(tmp_path: Path) -> None:
    plain = run_cli(["lint", str(GAP), "--format", "json", "--fail-on", "error"], cwd=tmp_path)
    assert plain.returncode == 0  # a 0.7 s gap is a warning on PX4 1.15
    (tmp_path / "fuzzoff.toml").write_text('severity = { OFB101 = "error" }\n')
    strict = run_cli(["lint", str(GAP), "--format", "json", "--fail-on", "error"], cwd=tmp_path)
    assert strict.returncode == 1
    levels = {f["code"]: f["severity"] for f in json.loads(strict.stdout)["files"][0]["findings"]}
    assert levels["OFB101"] == "error"


def test_threshold_option_reaches_the_rule(tmp_path: Path) -> None:
    (tmp_path / "fuzzoff.toml").write_text("options = { OFB101 = { max_gap_s = 0.8 } }\n")
    assert load_settings(tmp_path).option("OFB101", "max_gap_s") == 0.8
    result = run_cli(["lint", str(GAP), "--format", "json"], cwd=tmp_path)
    assert "OFB101" not in codes_of(result.stdout)  # the 0.7 s gap is now within the budget


def test_param_override_reaches_the_gate_model(tmp_path: Path) -> None:
    args = ["lint", str(GAP), "--format", "json"]
    assert "OFB103" not in codes_of(run_cli(args, cwd=tmp_path).stdout)
    lowered = run_cli([*args, "--param", "COM_OF_LOSS_T=0.5"], cwd=tmp_path)
    assert "OFB103" in codes_of(lowered.stdout)  # a 0.7 s gap now loses the signal


@pytest.mark.parametrize("value", ["nan", "inf", "fast", ""])
def test_param_option_takes_only_a_finite_number(tmp_path: Path, value: str) -> None:
    result = run_cli(["lint", str(GAP), "--param", f"COM_OF_LOSS_T={value}"], cwd=tmp_path)
    assert result.returncode == 2 and "expected NAME=NUMBER" in result.stderr


def test_fail_on_default_is_warning() -> None:
    assert load_settings(Path("/")).fail_on is Severity.WARNING


@pytest.mark.parametrize(
    ("content", "complaint"),
    [
        (b'[tool.fuzzoff]\nselect = ["OFB103"\n', "not valid TOML"),
        (b'[project]\nname = "caf\xe9"\n', "not UTF-8 text"),
    ],
)
def test_a_pyproject_that_cannot_be_read_is_an_error_not_skipped(
    tmp_path: Path, content: bytes, complaint: str
) -> None:
    """It may hold [tool.fuzzoff]: skipping it would let a parent folder's settings decide,
    and a CI job would pass on rules nobody chose."""
    (tmp_path / "fuzzoff.toml").write_text('select = ["OFB7"]\n')
    project = tmp_path / "project"
    project.mkdir()
    (project / "pyproject.toml").write_bytes(content)
    result = run_cli(["lint", str(GAP)], cwd=project)
    assert result.returncode == 2
    assert f"{project / 'pyproject.toml'}: {complaint}" in result.stderr
    assert "Traceback" not in result.stderr


def test_select_on_the_command_line_overrides_the_files_ignore(tmp_path: Path) -> None:
    """As in ruff: --select names the rules outright; --ignore and --extend-select add."""
    (tmp_path / "fuzzoff.toml").write_text('ignore = ["OFB101"]\n')
    args = ["lint", str(GAP), "--format", "json"]
    assert "OFB101" not in codes_of(run_cli(args, cwd=tmp_path).stdout)
    assert "OFB101" in codes_of(run_cli([*args, "--select", "OFB101"], cwd=tmp_path).stdout)
    extended = run_cli([*args, "--extend-select", "OFB101"], cwd=tmp_path)
    assert "OFB101" not in codes_of(extended.stdout)
