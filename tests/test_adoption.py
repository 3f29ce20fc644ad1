"""Switching fuzzoff on for a fleet with old flights (issue 30 item 2): a baseline of today's
findings, suppressions with a reason in the configuration, report-only runs, and the settings a
recording is judged with, all through the real command line."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

from tests.helpers import CORPORA, run_cli
from tests.report_fixtures import gap_recording
from tests.test_sarif import multitool, validate

OLD_FLIGHTS = ["stream_lost_in_offboard.tlog", "keepalive_gap_0_7s.tlog", "good_offboard.tlog"]


def fleet(tmp_path: Path) -> Path:
    """A folder of real corpus recordings, some with findings."""
    flights = tmp_path / "flights"
    flights.mkdir()
    for name in OLD_FLIGHTS:
        shutil.copy(CORPORA / "tlog" / name, flights / name)
    return flights


def lint_json(args: list[str], cwd: Path) -> tuple[int, dict[str, Any], str]:
    result = run_cli(["lint", *args, "--format", "json"], cwd=cwd)
    return result.returncode, json.loads(result.stdout), result.stderr


def test_a_baseline_passes_old_findings_and_fails_a_new_one(tmp_path: Path) -> None:
    flights = fleet(tmp_path)
    status, before, _ = lint_json(["flights"], tmp_path)
    assert status == 1
    old = sum(len(f["findings"]) for f in before["files"])

    written = run_cli(["lint", "flights", "--write-baseline", "fuzzoff-baseline.json"], tmp_path)
    assert written.returncode == 0, written.stderr  # recording the findings is the point
    assert f"{old} finding(s) of 3 recording(s) written" in written.stderr
    baseline = json.loads((tmp_path / "fuzzoff-baseline.json").read_text())
    assert {e["path"] for e in baseline["findings"]} <= {f"flights/{n}" for n in OLD_FLIGHTS}

    status, after, _ = lint_json(["flights", "--baseline", "fuzzoff-baseline.json"], tmp_path)
    assert status == 0
    assert all(not f["findings"] for f in after["files"])
    suppressed = [s for f in after["files"] for s in f["suppressed"]]
    assert len(suppressed) == old
    assert {s["suppression"]["kind"] for s in suppressed} == {"baseline"}

    # the same baseline from another working folder, the recordings named another way
    status, _, _ = lint_json(
        [str(flights), "--baseline", str(tmp_path / "fuzzoff-baseline.json")], flights
    )
    assert status == 0

    gap_recording(flights / "new_flight.tlog")
    status, data, _ = lint_json(["flights", "--baseline", "fuzzoff-baseline.json"], tmp_path)
    assert status == 1
    failing = {(Path(f["path"]).name, x["code"]) for f in data["files"] for x in f["findings"]}
    assert {name for name, _ in failing} == {"new_flight.tlog"}
    assert ("new_flight.tlog", "OFB101") in failing


def test_a_bad_baseline_is_a_usage_error_before_any_work(tmp_path: Path) -> None:
    fleet(tmp_path)
    (tmp_path / "b.json").write_text('{"findings": []}')
    result = run_cli(["lint", "flights", "--baseline", "b.json"], tmp_path)
    assert result.returncode == 2
    assert "not a fuzzoff baseline" in result.stderr
    assert (
        "missing.json"
        in run_cli(["lint", "flights", "--baseline", "missing.json"], tmp_path).stderr
    )


def test_exit_zero_and_fail_on_never_report_without_failing(tmp_path: Path) -> None:
    gap_recording(tmp_path / "gap.tlog")
    for extra in (["--exit-zero"], ["--fail-on", "never"]):
        result = run_cli(["lint", "gap.tlog", *extra], tmp_path)
        assert result.returncode == 0, extra
        assert "OFB101" in result.stdout
        assert "exit status 0 (--exit-zero)" in result.stdout
    (tmp_path / "fuzzoff.toml").write_text('fail-on = "never"\n')
    assert run_cli(["lint", "gap.tlog"], tmp_path).returncode == 0
    # an unreadable recording is still exit status 2: the lint did not see the flight
    (tmp_path / "broken.ulg").write_bytes(b"ULog\x01\x12" + b"\xff" * 64)
    assert run_cli(["lint", "broken.ulg", "--exit-zero"], tmp_path).returncode == 2


SUPPRESS = """
[tool.fuzzoff.suppressions]
"flights/gap.tlog" = [{ code = "OFB101", from = 1.5, to = 2.5, reason = "bench test, props off" }]
"""


def test_a_suppression_is_shown_with_its_reason_not_dropped(tmp_path: Path) -> None:
    (tmp_path / "flights").mkdir()
    gap_recording(tmp_path / "flights" / "gap.tlog")
    (tmp_path / "pyproject.toml").write_text(SUPPRESS)
    status, data, _ = lint_json(["flights", "--select", "OFB101"], tmp_path)
    assert status == 0
    (file,) = data["files"]
    assert file["findings"] == []
    (held,) = file["suppressed"]
    assert held["code"] == "OFB101" and held["time_s"] == 2.0
    assert held["suppression"] == {
        "kind": "config",
        "reason": "bench test, props off",
        "source": str(tmp_path / "pyproject.toml"),
        "from": 1.5,
        "to": 2.5,
    }
    html = run_cli(["lint", "flights", "--format", "html"], tmp_path)
    assert "Suppressed (1)" in html.stdout and "bench test, props off" in html.stdout
    terminal = run_cli(["lint", "flights", "--select", "OFB101"], tmp_path)
    assert "1 suppressed (1 by the config)" in terminal.stdout
    # outside its window the same code still fails
    (tmp_path / "pyproject.toml").write_text(SUPPRESS.replace("from = 1.5", "from = 2.1"))
    status, data, _ = lint_json(["flights", "--select", "OFB101"], tmp_path)
    assert status == 1 and data["files"][0]["suppressed"] == []


def test_a_suppression_needs_its_reason(tmp_path: Path) -> None:
    gap_recording(tmp_path / "gap.tlog")
    (tmp_path / "fuzzoff.toml").write_text('[suppressions]\n"gap.tlog" = [{ code = "OFB101" }]\n')
    result = run_cli(["lint", "gap.tlog"], tmp_path)
    assert result.returncode == 2
    assert "each suppression gives its reason" in result.stderr


def test_severity_and_config_on_the_command_line(tmp_path: Path) -> None:
    gap_recording(tmp_path / "gap.tlog")
    status, data, _ = lint_json(["gap.tlog", "--severity", "OFB1=info"], tmp_path)
    levels = {x["code"]: x["severity"] for x in data["files"][0]["findings"]}
    assert levels["OFB101"] == levels["OFB103"] == "info"
    assert status == 0
    bad = run_cli(["lint", "gap.tlog", "--severity", "OFB101"], tmp_path)
    assert bad.returncode == 2 and "CODE=LEVEL" in bad.stderr
    elsewhere = tmp_path / "settings" / "strict.toml"
    elsewhere.parent.mkdir()
    elsewhere.write_text('ignore = ["OFB1"]\n')
    (tmp_path / "fuzzoff.toml").write_text('select = ["OFB999"]\n')  # not read with --config
    status, data, _ = lint_json(["gap.tlog", "--config", str(elsewhere)], tmp_path)
    assert not any(x["code"].startswith("OFB1") for x in data["files"][0]["findings"])
    missing = run_cli(["lint", "gap.tlog", "--config", "nope.toml"], tmp_path)
    assert missing.returncode == 2 and "nope.toml" in missing.stderr


def test_show_settings_names_what_a_recording_is_judged_with(tmp_path: Path) -> None:
    (tmp_path / "flights").mkdir()
    gap_recording(tmp_path / "flights" / "gap.tlog")
    (tmp_path / "pyproject.toml").write_text(
        '[tool.fuzzoff]\nignore = ["OFB105"]\nparams = { COM_OF_LOSS_T = 0.5 }\n' + SUPPRESS
    )
    result = run_cli(
        ["lint", "--show-settings", "flights/gap.tlog", "--severity", "OFB102=error"], tmp_path
    )
    assert result.returncode == 0, result.stderr
    lines = dict(line.split(None, 1) for line in result.stdout.splitlines())
    assert lines["configuration"] == str(tmp_path / "pyproject.toml")
    assert lines["px4"] == "1.15 (assumed)" and lines["vehicle"] == "mc (detected)"
    assert lines["ignored"] == "OFB105"
    assert lines["severity"] == "OFB102=error"
    assert lines["params"] == "COM_OF_LOSS_T=0.5 (set in pyproject.toml)"
    assert lines["suppression"] == "OFB101 1.5-2.5 s: bench test, props off"
    folder = run_cli(["lint", "--show-settings", "."], tmp_path)
    assert folder.returncode == 0  # one recording found under it
    assert run_cli(["lint", "--show-settings", "nothing.tlog"], tmp_path).returncode == 2


def test_gate_takes_config_too(tmp_path: Path) -> None:
    gap_recording(tmp_path / "gap.tlog")
    (tmp_path / "alt.toml").write_text("params = { COM_OF_LOSS_T = 0.5 }\n")
    plain = run_cli(["gate", "gap.tlog"], tmp_path).stdout
    faster = run_cli(["gate", "gap.tlog", "--config", "alt.toml"], tmp_path).stdout
    assert "1.00-1.10 s after the newest keep-alive" in plain
    assert "0.50-0.60 s after the newest keep-alive" in faster


def test_sarif_keeps_a_suppressed_finding_as_suppressed(tmp_path: Path) -> None:
    """Code scanning would take a finding that left the SARIF for fixed: it stays, suppressed."""
    (tmp_path / "flights").mkdir()
    gap_recording(tmp_path / "flights" / "gap.tlog")
    (tmp_path / "pyproject.toml").write_text(SUPPRESS)
    result = run_cli(["lint", "flights", "--select", "OFB101", "--format", "sarif"], tmp_path)
    assert result.returncode == 0
    run = json.loads(result.stdout)["runs"][0]
    (held,) = [r for r in run["results"] if r.get("suppressions")]
    assert held["ruleId"] == "OFB101"
    assert held["suppressions"] == [
        {"kind": "external", "justification": "config: bench test, props off"}
    ]
    assert run["invocations"][0]["exitCode"] == 0
    sarif = tmp_path / "suppressed.sarif"
    sarif.write_text(result.stdout, encoding="utf-8")
    assert validate(multitool(), [sarif], tmp_path / "validation.sarif") == []
