"""A live flight over PX4's ROS 2 bridge (``fuzzoff sitl run example --transport ros2``).

Runs in ``make test`` when a bundle with the bridge (``../shared/px4-sitl/1.16.2-ros2``), the
cyclonedds package (the ``ros2live`` extra) and a private network namespace (root, ``unshare``)
are all there; skipped, saying which is missing, otherwise. One PX4 boot, about 30 s.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from fuzzoff.catalog import get_rule
from fuzzoff.sitl import bundle
from fuzzoff.sitl.ros2.run import missing
from tests.helpers import CORPORA, run_cli, run_cli_process


def _why_not() -> str | None:
    try:
        bundle.find_bridge_build("1.16.2", None)
    except bundle.BundleError as exc:
        return str(exc)
    return missing()


WHY_NOT = _why_not()


@pytest.mark.skipif(WHY_NOT is not None, reason=f"live ROS 2 flight: {WHY_NOT}")
def test_the_ros2_example_flies_over_the_bridge_and_its_bag_lints_clean(tmp_path: Path) -> None:
    save = tmp_path / "flight"
    out = run_cli_process(
        [
            "sitl",
            "run",
            "example",
            "--transport",
            "ros2",
            "--release",
            "1.16.2",
            "--save-dir",
            str(save),
            "--format",
            "json",
        ],
        timeout=300,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    summary = json.loads(out.stdout)
    assert summary["release"] == "1.16.2-ros2"
    # PX4 answered the switch (176) and the arm (400) over DDS
    assert {a["command"] for a in summary["acks"]} >= {176, 400}
    assert summary["counts"]["/fmu/in/trajectory_setpoint"] > 100
    for recording in summary["recordings"]:
        assert Path(recording).exists(), recording
    bag = save / "example-1.16.2-ros2-mcap"
    lint = run_cli(["lint", str(bag), "--format", "json"])
    (report,) = json.loads(lint.stdout)["files"]
    assert lint.returncode == 0, [f["message"] for f in report["findings"]]
    assert report["profile"]["px4"] == "1.16"
    assert os.listdir(save)


MATRIX = os.environ.get("FUZZOFF_SITL_MATRIX") == "1"
MATRIX_BUNDLES = ("1.16.2", "1.18.0")
ROVER_BUNDLES = ("1.17.0", "1.18.0")
"""The bridge bundles built with the rover modules that fly the rover (not main: see below)."""
MAIN_BUNDLE = "main"
"""main-2026-08-13 flies the standard VTOL and the airplane programs (issue 33)."""


def _matrix() -> list[object]:
    from fuzzoff.sitl.airframes import DOES_NOT_FLY
    from fuzzoff.sitl.ros2.programs import FW_PROGRAMS, PROGRAMS, VTOL_PROGRAMS

    params = [
        pytest.param(name, release, id=f"{name}-{release}")
        for name, program in PROGRAMS.items()
        for release in (ROVER_BUNDLES if program.rover is not None else MATRIX_BUNDLES)
    ]
    params += [
        pytest.param(p.name, MAIN_BUNDLE, id=f"{p.name}-{MAIN_BUNDLE}")
        for p in (*VTOL_PROGRAMS, *FW_PROGRAMS)
    ]
    why = DOES_NOT_FLY[("main", "sihsim_rover_ackermann")]
    params += [
        pytest.param(name, "main", id=f"{name}-main", marks=pytest.mark.skip(reason=why))
        for name, program in PROGRAMS.items()
        if program.rover is not None
    ]
    return params


ARM = 400  # MAV_CMD_COMPONENT_ARM_DISARM
LOST_ARM_ATTEMPTS = 3
"""The lost ARM (``example_arm_lost``) goes through a publisher made just before it: PX4 never
gets it while DDS discovery has not matched that publisher, which a loaded machine can delay
past the write. A flight where PX4 answered the ARM did not fly the hazard: it is flown again."""


@pytest.mark.skipif(WHY_NOT is not None, reason=f"live ROS 2 flight: {WHY_NOT}")
@pytest.mark.skipif(not MATRIX, reason="the whole matrix runs with make test-sitl")
@pytest.mark.parametrize(("program", "release"), _matrix())
def test_every_ros2_program_flies_and_its_bags_say_what_it_is(
    program: str, release: str, tmp_path: Path
) -> None:
    """Each program on each bridge release: the flight is flown and recorded, and a clean one
    lints clean, a hazard gives its error, where fuzzoff already reports it (``missed``); on
    the VTOL and airplane flights the gate model, run on the bag, agrees with PX4's ULog on
    every switch, arm, loss, failsafe action, return and disarm."""
    from fuzzoff.sitl.ros2.programs import PROGRAMS

    spec = PROGRAMS[program]
    args = ["sitl", "run", program, "--transport", "ros2", "--release", release]
    for attempt in range(LOST_ARM_ATTEMPTS):
        save = tmp_path / str(attempt)
        out = run_cli_process([*args, "--save-dir", str(save), "--format", "json"], timeout=300)
        assert out.returncode == 0, out.stdout + out.stderr
        summary = json.loads(out.stdout)
        arm_answered = any(a["command"] == ARM for a in summary["acks"])
        if not (spec.plan.arm_from_new_publisher and arm_answered):
            break
    else:  # discovery beat the ARM every time: the hazard was never flown
        pytest.fail(f"PX4 answered the ARM in {LOST_ARM_ATTEMPTS} flights of {program}")
    bag = next(Path(p) for p in summary["recordings"] if p.endswith("-mcap"))
    if spec.vtol is not None:  # the VTOL and airplane programs: the model against PX4's ULog
        from fuzzoff.sitl.ros2.verdict import compare

        ulog = next(Path(p) for p in summary["recordings"] if p.endswith(".ulg"))
        verdict = compare(bag, release, ulog, vehicle=spec.vehicle or "mc")
        assert not [i for i in verdict.items if i.agree is False], [
            (i.what, i.px4, i.model) for i in verdict.items
        ]
    lint = run_cli(["lint", str(bag), *spec.lint_args, "--format", "json"])
    (report,) = json.loads(lint.stdout)["files"]
    if spec.missed is not None:
        return
    if spec.kind == "clean":
        assert lint.returncode == 0, [f["message"] for f in report["findings"]]
    else:  # its error, or its warning for a rule that warns (OFB501)
        assert any(
            f["code"] in spec.codes and f["severity"] == get_rule(f["code"]).severity.label
            for f in report["findings"]
        ), [f["message"] for f in report["findings"]]


@pytest.mark.skipif(WHY_NOT is not None, reason=f"live ROS 2 flight: {WHY_NOT}")
@pytest.mark.skipif(not MATRIX, reason="the whole matrix runs with make test-sitl")
def test_a_recorded_bag_replayed_over_the_bridge_makes_px4_do_it_again(tmp_path: Path) -> None:
    """``sitl replay BAG --transport ros2``: the node's stream stops 6 s after the arm in the
    recording, and PX4 runs its loss failsafe again."""
    bag = CORPORA / "ros2bridge" / "example_stops-1.16.2-ros2-mcap"
    args = ["sitl", "replay", str(bag), "--transport", "ros2", "--release", "1.16.2"]
    out = run_cli_process([*args, "--save-dir", str(tmp_path), "--format", "json"], timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    summary = json.loads(out.stdout)
    assert {a["command"] for a in summary["acks"]} >= {176, 400}
    assert any(failsafe for *_, failsafe in summary["modes"])
