"""Configuration as a user writes it: select/ignore by prefix, severities, thresholds, params."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from fuzzoff import releases
from fuzzoff.config import ConfigError, find_config, load_settings
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


@pytest.mark.parametrize(
    ("content", "found"),
    [
        (b'[tool.fuzzoff]\nselect = ["OFB7"]\n', True),
        (b'[tool."fuzz\\u006Fff"]\nselect = ["OFB7"]\n', True),  # a quoted key with escapes
        (b'tool.fuzzoff.select = ["OFB7"]\n', True),
        (b"[tool.ruff]\nline-length = 100\n", False),
        (b'[project\nname = "not TOML, and no table of ours"\n', False),
    ],
)
def test_a_pyproject_is_a_configuration_only_with_a_fuzzoff_table(
    tmp_path: Path, content: bytes, found: bool
) -> None:
    """A file that cannot name the table is passed by unparsed (issue 31), even when it is not
    valid TOML: the folder above decides, as for any pyproject.toml without the table."""
    (tmp_path / "fuzzoff.toml").write_text('select = ["OFB1"]\n')
    project = tmp_path / "project"
    project.mkdir()
    (project / "pyproject.toml").write_bytes(content)
    expected = project / "pyproject.toml" if found else tmp_path / "fuzzoff.toml"
    assert find_config(project) == expected
    prefixes = {code[:4] for code in load_settings(project).select}
    assert prefixes == ({"OFB7"} if found else {"OFB1"})


def test_select_on_the_command_line_overrides_the_files_ignore(tmp_path: Path) -> None:
    """As in ruff: --select names the rules outright; --ignore and --extend-select add."""
    (tmp_path / "fuzzoff.toml").write_text('ignore = ["OFB101"]\n')
    args = ["lint", str(GAP), "--format", "json"]
    assert "OFB101" not in codes_of(run_cli(args, cwd=tmp_path).stdout)
    assert "OFB101" in codes_of(run_cli([*args, "--select", "OFB101"], cwd=tmp_path).stdout)
    extended = run_cli([*args, "--extend-select", "OFB101"], cwd=tmp_path)
    assert "OFB101" not in codes_of(extended.stdout)


# --- each recording's nearest configuration, per-file-ignores, as ruff ------------------------


def _lint_json(args: list[str], cwd: Path) -> tuple[int, dict[str, dict[str, Any]], str]:
    """Run lint as JSON from ``cwd``: the exit status, each file by name, the standard error."""
    result = run_cli(["lint", *args, "--format", "json"], cwd=cwd)
    files = {Path(f["path"]).name: f for f in json.loads(result.stdout)["files"]}
    return result.returncode, files, result.stderr


def _codes(file: dict[str, Any]) -> set[str]:
    return {f["code"] for f in file["findings"]}


def _flights(root: Path) -> tuple[Path, Path]:
    """root/a.tlog and root/rover/b.tlog, both the corpus's 0.7 s gap (OFB101 on each)."""
    (root / "rover").mkdir(parents=True)
    a, b = root / "a.tlog", root / "rover" / "b.tlog"
    a.write_bytes(GAP.read_bytes())
    b.write_bytes(GAP.read_bytes())
    return a, b


def test_each_recording_takes_the_nearest_configuration_above_it(tmp_path: Path) -> None:
    _flights(tmp_path)
    (tmp_path / "fuzzoff.toml").write_text('ignore = ["OFB101"]\n')
    (tmp_path / "rover" / "pyproject.toml").write_text(
        '[tool.fuzzoff]\nvehicle = "rover-ackermann"\n'
    )
    _, files, _ = _lint_json(["."], tmp_path)
    assert "OFB101" not in _codes(files["a.tlog"])
    assert files["a.tlog"]["profile"]["vehicle"] == "mc"
    # rover/ has its own settings: the root's ignore does not reach it (as in ruff)
    assert "OFB101" in _codes(files["b.tlog"])
    assert files["b.tlog"]["profile"]["vehicle"] == "rover-ackermann"
    assert files["b.tlog"]["profile"]["vehicle_source"] == "user"
    # the same from inside rover/, naming the other recording by its path
    _, files, _ = _lint_json([str(tmp_path / "a.tlog"), "."], tmp_path / "rover")
    assert "OFB101" not in _codes(files["a.tlog"]) and "OFB101" in _codes(files["b.tlog"])


def test_the_command_line_applies_over_every_configuration(tmp_path: Path) -> None:
    _flights(tmp_path)
    (tmp_path / "rover" / "fuzzoff.toml").write_text('vehicle = "rover-ackermann"\n')
    _, files, _ = _lint_json([".", "--vehicle", "fw", "--ignore", "OFB101"], tmp_path)
    assert {f["profile"]["vehicle"] for f in files.values()} == {"fw"}
    assert not any("OFB101" in _codes(f) for f in files.values())


def test_a_recording_with_no_configuration_above_it_takes_the_current_folders(
    tmp_path: Path,
) -> None:
    flights, project = tmp_path / "flights", tmp_path / "project"
    flights.mkdir()
    project.mkdir()
    (flights / "a.tlog").write_bytes(GAP.read_bytes())
    (project / "fuzzoff.toml").write_text('ignore = ["OFB101"]\n')
    _, files, _ = _lint_json([str(flights)], project)
    assert "OFB101" not in _codes(files["a.tlog"])


def test_a_mistake_in_a_nested_configuration_stops_the_run_before_any_work(
    tmp_path: Path,
) -> None:
    _flights(tmp_path)
    (tmp_path / "rover" / "fuzzoff.toml").write_text('vehicle = "rover"\n')
    result = run_cli(["lint", "."], cwd=tmp_path)
    assert result.returncode == 2 and result.stdout == ""
    assert f"{tmp_path / 'rover' / 'fuzzoff.toml'}: vehicle type 'rover' names no rover kind" in (
        result.stderr
    )


def test_fail_on_is_the_runs_and_a_nested_one_says_it_is_not_used(tmp_path: Path) -> None:
    _flights(tmp_path)
    (tmp_path / "fuzzoff.toml").write_text('fail-on = "info"\n')
    (tmp_path / "rover" / "fuzzoff.toml").write_text('fail-on = "error"\n')
    status, _, stderr = _lint_json(["."], tmp_path)
    assert status == 1  # the 0.7 s gaps are info; the run's fail level (the root's) is info
    assert stderr.count("fail-on is not used") == 1
    assert "rover" in stderr and "info" in stderr


@pytest.mark.parametrize(
    ("pattern", "ignored_in"),
    [
        ("a.tlog", {"a.tlog"}),  # no slash: the name, in any folder
        ("*.tlog", {"a.tlog", "b.tlog"}),
        ("rover/*", {"b.tlog"}),  # a slash: relative to the configuration's folder
        ("*/b.tlog", {"b.tlog"}),
        ("**/b.tlog", {"b.tlog"}),
        ("*.{ulg,tlog}", {"a.tlog", "b.tlog"}),
        ("!rover/**", {"a.tlog"}),  # negated: everywhere else
        ("r*/a.tlog", set()),
    ],
)
def test_per_file_ignores_follow_ruffs_globs(
    tmp_path: Path, pattern: str, ignored_in: set[str]
) -> None:
    _flights(tmp_path)
    (tmp_path / "pyproject.toml").write_text(
        f'[tool.fuzzoff.per-file-ignores]\n{json.dumps(pattern)} = ["OFB1"]\n'
    )
    _, files, _ = _lint_json(["."], tmp_path)
    without = {
        name for name, f in files.items() if not any(c.startswith("OFB1") for c in _codes(f))
    }
    assert without == ignored_in
    assert all("OFB701" in _codes(f) for f in files.values())  # other rules untouched


def test_per_file_ignores_mistakes_are_usage_errors(tmp_path: Path) -> None:
    (tmp_path / "fuzzoff.toml").write_text('per-file-ignores = { "*.tlog" = ["OFB9"] }\n')
    result = run_cli(["lint", str(GAP)], cwd=tmp_path)
    assert result.returncode == 2 and "OFB9" in result.stderr
    (tmp_path / "fuzzoff.toml").write_text('per-file-ignores = { "*.{tlog" = ["OFB1"] }\n')
    result = run_cli(["lint", str(GAP)], cwd=tmp_path)
    assert result.returncode == 2 and "bad pattern" in result.stderr


def test_lint_without_a_path_lints_the_current_folder(tmp_path: Path) -> None:
    _flights(tmp_path)
    status, files, _ = _lint_json([], tmp_path)
    assert status == 0 and set(files) == {"a.tlog", "b.tlog"}  # the 0.7 s gaps are info
    empty = tmp_path / "empty"
    empty.mkdir()
    result = run_cli(["lint"], cwd=empty)
    assert result.returncode == 2 and "no recordings in ." in result.stderr


@pytest.mark.parametrize(
    ("args", "hint"),
    [
        (["lint", "--statistcs", "x"], "did you mean --statistics?"),
        (["lint", "--fail-on=warnng", "x"], "did you mean warning?"),
        (["lint", "--format", "htm", "x"], "did you mean html?"),
        (["lnt", "x"], "did you mean lint?"),
        (["lint", "--px4", "mian", "x"], "did you mean main?"),
        (["lint", "--vehicle", "rover-ackerman", "x"], "did you mean rover-ackermann?"),
    ],
)
def test_a_mistyped_option_gets_a_did_you_mean(args: list[str], hint: str) -> None:
    result = run_cli(args)
    assert result.returncode == 2 and hint in result.stderr
    assert result.stderr.count("\n") == 1


@pytest.mark.parametrize(
    ("text", "hint"),
    [
        ('selct = ["OFB1"]', "unknown key selct (did you mean select?)"),
        ("per-file-ignore = {}", "did you mean per-file-ignores?"),
        ("options = { OFB104 = { stale_ss = 0.3 } }", "did you mean stale_s?"),
        ("options = { OFB1044 = { stale_s = 0.3 } }", "did you mean OFB104?"),
    ],
)
def test_a_mistyped_key_gets_a_did_you_mean(tmp_path: Path, text: str, hint: str) -> None:
    (tmp_path / "fuzzoff.toml").write_text(text + "\n")
    result = run_cli(["lint", str(GAP)], cwd=tmp_path)
    assert result.returncode == 2 and hint in result.stderr


_MAJOR, _MINOR = releases.newest_listed()
_NEWEST, _PAST = f"{_MAJOR}.{_MINOR}", f"{_MAJOR}.{_MINOR + 1}.0"
"""The newest release modelled (1.18), and one past it, read from the release table."""


@pytest.mark.parametrize(
    ("value", "complaint"),
    [
        (
            "2.0",
            f"PX4 2.0 is not modelled: the newest release modelled is {_NEWEST}; give --px4 main",
        ),
        (_PAST, f"PX4 {_PAST} is not modelled"),
        ("1.4", "PX4 1.4 is not modelled: the oldest release modelled is 1.5"),
    ],
)
def test_a_px4_release_that_is_not_modelled_is_an_error(value: str, complaint: str) -> None:
    result = run_cli(["lint", str(GAP), "--px4", value])
    assert result.returncode == 2 and f"error: --px4: {complaint}" in result.stderr


@pytest.mark.parametrize(
    ("value", "profile"),
    [("1.12", "1.13"), ("1.12.3", "1.13"), ("1.7", "legacy")],
)
def test_a_release_judged_by_another_profile_says_which(value: str, profile: str) -> None:
    result = run_cli(["lint", str(GAP), "--px4", value, "--format", "json"])
    assert json.loads(result.stdout)["files"][0]["profile"]["px4"] == profile
    assert (
        f"fuzzoff: --px4: PX4 {'.'.join(value.split('.')[:2])} is judged with profile {profile}"
        in (result.stderr)
    )
    plain = run_cli(["lint", str(GAP), "--px4", "1.15.4", "--format", "json"])
    assert "judged with profile" not in plain.stderr


def test_vehicle_rover_alone_is_an_error_naming_the_kinds() -> None:
    result = run_cli(["lint", str(GAP), "--vehicle", "rover"])
    assert result.returncode == 2
    assert "rover-ackermann, rover-differential, rover-mecanum" in result.stderr


def test_params_say_where_they_were_set(tmp_path: Path) -> None:
    def ofb701(args: list[str]) -> str:
        result = run_cli(["lint", str(GAP), "--format", "json", *args], cwd=tmp_path)
        found = json.loads(result.stdout)["files"][0]["findings"]
        return next(f["message"] for f in found if f["code"] == "OFB701")

    (tmp_path / "pyproject.toml").write_text("[tool.fuzzoff]\nparams = { COM_OF_LOSS_T = 0.5 }\n")
    assert "COM_OF_LOSS_T 0.5 s (set in pyproject.toml)" in ofb701([])
    assert "command line" not in ofb701([])
    assert "COM_OF_LOSS_T 0.4 s (set with --param)" in ofb701(["--param", "COM_OF_LOSS_T=0.4"])
