"""Live runs against real PX4 SITL bundles (``../shared/px4-sitl``, or ``$FUZZOFF_PX4_SITL``).

``make test`` runs two short checks on one release (the issue's acceptance: ``fuzzoff replay
corpora/tlog/stream_lost_in_offboard.tlog --to udp:127.0.0.1:14580+N`` against a running bundle
prints PX4's outcome and the model's, and they agree; and a live fuzz campaign of one stream,
``fuzzoff fuzz --against sitl:1.16.2 --examples 1``); ``make test-sitl``
(``FUZZOFF_SITL_MATRIX=1``) runs every scenario on every bundled release with ``fuzzoff sitl
run``, each compared with the gate model. Both are skipped, saying why, without the bundles.

Each pytest worker uses its own PX4 instance (2 or 3) so that two runs never share ports.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from fuzzoff.sitl import bundle
from fuzzoff.sitl.scenarios import (
    SCENARIOS,
    VEHICLE_RELEASES,
    scenarios_for,
    vehicle_scenarios,
    why_not_run,
)
from tests.helpers import CORPORA, run_cli_process

RELEASES = bundle.releases()
QUICK_RELEASE = "1.16.2"
"""The short check's release: it is ready to arm 5 s after boot (1.15 needs 40 s)."""
MATRIX = os.environ.get("FUZZOFF_SITL_MATRIX") == "1"

needs_bundles = pytest.mark.skipif(
    not RELEASES,
    reason=f"no PX4 SITL bundles in {bundle.default_root()} (set FUZZOFF_PX4_SITL)",
)


def _instance() -> int:
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw1")
    return 2 if worker == "gw0" else 3


@needs_bundles
def test_replay_to_a_running_px4_prints_its_outcome_beside_the_models(tmp_path: Path) -> None:
    release = QUICK_RELEASE if QUICK_RELEASE in RELEASES else RELEASES[-1]
    build = bundle.find_build(release, None)
    instance = _instance()
    px4 = bundle.start(build, instance)
    try:
        target = f"udp:127.0.0.1:{px4.listen_port}"
        record = tmp_path / "exchange.tlog"
        out = run_cli_process(
            [
                "replay",
                str(CORPORA / "tlog" / "stream_lost_in_offboard.tlog"),
                "--to",
                target,
                "--record",
                str(record),
                "--connect-timeout",
                "30",
            ],
            timeout=240,
        )
    finally:
        px4.stop()
        px4.cleanup()
    assert out.returncode == 0, out.stdout + out.stderr
    assert "switch to OFFBOARD PX4: accepted" in out.stdout
    assert "failsafe action    PX4: POSCTL" in out.stdout
    assert "automatic return   PX4: back to OFFBOARD" in out.stdout
    assert "verdict: PX4 and the model agree" in out.stdout
    assert record.stat().st_size > 0


@needs_bundles
def test_a_live_campaign_sends_a_generated_stream_and_judges_what_px4_did(tmp_path: Path) -> None:
    """``fuzzoff fuzz --against``: one stream drawn, sent to a PX4 the campaign starts, judged
    beside the gate model (a disagreement is confirmed and saved, not shrunk here)."""
    release = QUICK_RELEASE if QUICK_RELEASE in RELEASES else RELEASES[-1]
    saved = tmp_path / "reproducers"
    out = run_cli_process(
        [
            "fuzz",
            "--against",
            f"sitl:{release}",
            "--examples",
            "1",
            "--shrink-runs",
            "0",
            "--instance",
            str(_instance()),
            "--save-dir",
            str(saved),
        ],
        timeout=300,
    )
    assert out.returncode in (0, 1), out.stdout + out.stderr
    assert f"fuzzoff fuzz --against sitl:{release}" in out.stdout
    assert "streams       1 sent" in out.stdout
    assert "switch to OFFBOARD: accepted" in out.stdout
    assert "fuzzoff: search 1:" in out.stderr
    if out.returncode == 1:
        assert list(saved.glob("px4-*.expected.json")), out.stdout
    else:
        assert not saved.exists()


def _matrix() -> list[object]:
    """Each release's scenarios; one its bundle cannot run (``why_not_run``: main's SIH clock
    stopping) is skipped with the reason."""
    return [
        pytest.param(
            release,
            name,
            id=f"{name}-{release}",
            marks=[pytest.mark.skip(reason=r)] if (r := why_not_run(release, name)) else [],
        )
        for release in RELEASES
        for name in scenarios_for(release)
    ]


@needs_bundles
@pytest.mark.skipif(not MATRIX, reason="the whole matrix runs with make test-sitl")
@pytest.mark.parametrize(("release", "scenario"), _matrix())
def test_px4_and_the_gate_model_agree_on_a_scenario(
    release: str, scenario: str, tmp_path: Path
) -> None:
    save = tmp_path / "run"
    out = run_cli_process(
        [
            "sitl",
            "run",
            scenario,
            "--release",
            release,
            "--instance",
            str(_instance()),
            "--save-dir",
            str(save),
        ],
        timeout=400,
    )
    assert out.returncode == 0, out.stdout + out.stderr


def _vehicle_matrix() -> list[object]:
    """Every other vehicle's scenario on each bundle that has its airframe; a bundle that has
    it but cannot fly it (main's rover) is skipped with the reason (``airframes.why_not``)."""
    from fuzzoff.sitl.airframes import airframe_for, why_not

    cases: list[object] = []
    for release in RELEASES:
        if release not in VEHICLE_RELEASES:
            continue
        build = bundle.find_build(release, None)
        for name in vehicle_scenarios():
            reason = why_not(build, airframe_for(SCENARIOS[name].vehicle))
            flies_on = SCENARIOS[name].flies_on
            if reason is None and flies_on is not None and release not in flies_on:
                reason = f"{name} flies on {', '.join(flies_on)} only (docs/sitl.md)"
            if reason is not None and "no SIH airframe" not in reason and "without" not in reason:
                marks = [pytest.mark.skip(reason=reason)]
            elif reason is not None:
                continue  # the build lacks the vehicle altogether: nothing to say per run
            else:
                marks = []
            cases.append(pytest.param(release, name, id=f"{name}-{release}", marks=marks))
    return cases


@needs_bundles
@pytest.mark.skipif(not MATRIX, reason="the vehicles' matrix runs with make test-sitl")
@pytest.mark.parametrize(("release", "scenario"), _vehicle_matrix())
def test_px4_and_the_gate_model_agree_on_another_vehicle(
    release: str, scenario: str, tmp_path: Path
) -> None:
    """Issue 33: the hexacopter, standard VTOL, tailsitter, airplane and Ackermann rover
    scenarios, each on its own SIH airframe, compared with the gate model for that vehicle."""
    out = run_cli_process(
        [
            "sitl",
            "run",
            scenario,
            "--release",
            release,
            "--instance",
            str(_instance()),
            "--save-dir",
            str(tmp_path / "run"),
        ],
        timeout=600,
    )
    assert out.returncode == 0, out.stdout + out.stderr
