"""The release records are the one place a release's behaviour is written: for every record, the
gate does on a tiny stream what the record says, and a record added to the table (here, in a
test only) is a profile ``fuzzoff profiles`` lists and a lint judges with, nothing else edited."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from fuzzoff import releases
from fuzzoff.events import Command, SetAttitudeTarget
from fuzzoff.fuzz.streams import echo
from fuzzoff.gate import GateModel
from fuzzoff.profiles import Profile, px4_profile_for
from fuzzoff.releases import Release
from tests.gate.streams import (
    LOITER,
    OFFBOARD,
    POSCTL,
    TERMINATION,
    arm,
    flags,
    in_offboard,
    loss_times,
    ocm,
    of,
    run,
    status,
    stream,
    switch_mode,
    switch_offboard,
)
from tests.helpers import CORPORA, ROOT, run_cli

RELEASES = list(releases.RELEASES)
NAMES = [r.name for r in RELEASES]
FRAMEWORK = [r for r in RELEASES if r.loss_failsafe == "framework"]


def by_name(release: Release) -> str:
    return release.name


@pytest.mark.parametrize("release", RELEASES, ids=by_name)
def test_a_disarmed_switch_without_a_stream_is_accepted_as_the_record_says(
    release: Release,
) -> None:
    events = [status(0.0, POSCTL, False, POSCTL), switch_offboard(1.0)]
    trs = run(release.name, events)
    assert bool(of("request_accepted", trs)) is release.accepts_disarmed_switch
    assert bool(of("request_rejected", trs)) is not release.accepts_disarmed_switch


@pytest.mark.parametrize("release", [r for r in RELEASES if r.accepts_disarmed_switch], ids=by_name)
def test_arming_in_offboard_without_a_stream_is_checked_as_the_record_says(
    release: Release,
) -> None:
    events = [status(0.0, POSCTL, False, POSCTL), switch_offboard(1.0), arm(2.0)]
    trs = run(release.name, events)
    assert bool(of("arm_rejected", trs)) is release.checks_signal_at_arming


@pytest.mark.parametrize("release", RELEASES, ids=by_name)
def test_arming_in_position_mode_without_manual_control_as_the_record_says(
    release: Release,
) -> None:
    """Disarmed in Position with the joystick lost, then an arm: refused where Position's
    requirement (manual control) is checked at arming, accepted where it is not; with manual
    control it is accepted everywhere."""
    lost = flags(0.0, manual_control_signal_lost=True)
    refused = of(
        "arm_rejected", run(release.name, [lost, status(0.0, POSCTL, False, POSCTL), arm(1.0)])
    )
    assert bool(refused) is release.arming_needs_manual_in_stick_modes
    if refused:
        assert "no manual control, which POSCTL needs" in refused[0].message
    kept = flags(0.0, manual_control_signal_lost=False)
    assert not of(
        "arm_rejected", run(release.name, [kept, status(0.0, POSCTL, False, POSCTL), arm(1.0)])
    )


@pytest.mark.parametrize("release", RELEASES, ids=by_name)
def test_a_mavlink_mode_switch_is_acked_as_often_as_the_record_says(release: Release) -> None:
    switch = Command(t=1.0, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    answers = echo([switch], release.name, "mc", {}, acks=True, status=False, transport="mavlink")
    assert len(answers) == (2 if release.acks_switch_twice else 1)


@pytest.mark.parametrize("release", FRAMEWORK, ids=by_name)
def test_the_loss_action_without_manual_control_follows_nav_rcl_act_as_the_record_says(
    release: Release,
) -> None:
    """COM_OBL_RC_ACT 0 (Position) with no manual control: NAV_RCL_ACT's Return where the
    record falls back to it, else Position as configured."""
    events = [flags(0.0, manual_control_signal_lost=True), in_offboard(), *stream(0.0, 1.0)]
    trs = run(release.name, events, t_end=3.0)
    expected = "POSCTL" if release.nav_rcl_fallback == "none" else "AUTO_RTL"
    assert [t.action for t in of("failsafe", trs)] == [expected]


@pytest.mark.parametrize("release", RELEASES, ids=by_name)
def test_set_nav_state_is_handled_as_the_record_says(release: Release) -> None:
    set_nav_state = Command(t=1.0, command=100001, params=(float(OFFBOARD), 0, 0, 0, 0, 0, 0))
    trs = run(release.name, [status(0.0, POSCTL, False, POSCTL), set_nav_state])
    assert bool(of("request_accepted", trs)) is (
        release.handles_set_nav_state and release.accepts_disarmed_switch
    )


@pytest.mark.parametrize("release", RELEASES, ids=by_name)
def test_an_attitude_target_without_thrust_keeps_the_stream_as_the_record_says(
    release: Release,
) -> None:
    """SET_ATTITUDE_TARGET with the thrust ignored (type_mask 71): a keep-alive unless the
    record's receiver needs the thrust."""
    target = SetAttitudeTarget(t=1.0, type_mask=71, target_system=1, target_component=1)
    trs = run(release.name, [status(0.0, LOITER, True, LOITER), target], t_end=1.05)
    assert bool(of("signal_available", trs)) is not release.attitude_target_needs_thrust


@pytest.mark.parametrize("release", FRAMEWORK, ids=by_name)
def test_an_unknown_main_mode_is_answered_as_the_record_says(release: Release) -> None:
    trs = run(release.name, [status(0.0, POSCTL, True, POSCTL), switch_mode(1.0, 42)])
    rejected = release.unsupported_main_mode == "rejected"
    assert any("no such mode" in (t.message or "") for t in trs)
    assert any("rejected" in t.message for t in trs) is rejected


@pytest.mark.parametrize("release", FRAMEWORK, ids=by_name)
def test_termination_is_left_or_not_as_the_record_says(release: Release) -> None:
    events = [status(0.0, TERMINATION, True, TERMINATION), *stream(0.0, 1.0), switch_offboard(0.5)]
    rejected = bool(of("request_rejected", run(release.name, events)))
    assert rejected is release.never_leaves_termination


@pytest.mark.parametrize("release", FRAMEWORK, ids=by_name)
def test_the_acceleration_flag_needs_the_estimate_the_record_names(release: Release) -> None:
    """Without a velocity estimate the acceleration flag keeps the signal only where it needs
    the attitude instead; without an attitude estimate, only where it needs the velocity."""
    no_velocity = [flags(0.0, local_velocity_valid=False), ocm(1.0, acceleration=True)]
    no_attitude = [flags(0.0, attitude_valid=False), ocm(1.0, acceleration=True)]
    needs_attitude = release.acceleration_needs_attitude
    assert bool(of("signal_available", run(release.name, no_velocity))) is needs_attitude
    assert bool(of("signal_available", run(release.name, no_attitude))) is not needs_attitude


@pytest.mark.parametrize("release", FRAMEWORK, ids=by_name)
def test_the_attitude_flag_needs_an_attitude_estimate_as_the_record_says(
    release: Release,
) -> None:
    events = [flags(0.0, attitude_valid=False), ocm(1.0, attitude=True)]
    available = bool(of("signal_available", run(release.name, events)))
    assert available is not release.attitude_flag_needs_attitude


@pytest.mark.parametrize("release", RELEASES, ids=by_name)
def test_the_signal_is_lost_after_the_records_timeout(release: Release) -> None:
    """The last keep-alive at 1 s: the signal is lost after the fixed time where the record has
    one, else after its default COM_OF_LOSS_T (up to one check pass and loop later)."""
    timeout = release.fixed_loss_s
    if timeout is None:
        timeout = release.param_defaults["COM_OF_LOSS_T"]
    model = GateModel(Profile(px4=px4_profile_for(release.name)), {}, "1")
    assert model.loss_timeout == timeout
    (lost,) = loss_times(run(release.name, [in_offboard(), *stream(0.0, 1.0)], t_end=4.0))
    assert 1.0 + timeout <= lost + 1e-9 <= 1.0 + timeout + 0.25


@pytest.mark.parametrize("release", RELEASES, ids=by_name)
def test_a_release_names_its_own_profile(release: Release) -> None:
    assert px4_profile_for(release.name) == release.name
    for minor in release.minors:
        assert px4_profile_for(f"1.{minor}.2") == release.name


NEWEST_MINOR = releases.newest_listed()[1]
NEXT = f"1.{NEWEST_MINOR + 1}"
"""The release after the newest modelled one (``1.19`` while 1.18 is the newest)."""


def test_versions_past_the_newest_release_are_main_and_before_the_oldest_legacy() -> None:
    assert px4_profile_for(f"{NEXT}.0") == px4_profile_for("2.0") == "main"
    assert px4_profile_for("1.4.1") == px4_profile_for("0.9") == "legacy"


# A made-up release, added to the table in a fresh interpreter only -----------------------------

_WITH_EXTRA = textwrap.dedent(
    """
    import dataclasses, sys
    from fuzzoff import releases
    newest = releases.RELEASES[-2]
    minor = releases.newest_listed()[1] + 1
    extra = dataclasses.replace(
        newest,
        name=f"1.{minor}",
        covers=f"v1.{minor}: made up by a test",
        minors=(minor,),
        acks_switch_twice=True,
    )
    releases.RELEASES = (*releases.RELEASES[:-1], extra, releases.RELEASES[-1])
    from fuzzoff.cli import main
    sys.exit(main(sys.argv[1:]))
    """
)


def _with_extra(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", _WITH_EXTRA, *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_a_new_record_is_a_profile_fuzzoff_profiles_lists() -> None:
    done = _with_extra("profiles", "--format", "json")
    assert done.returncode == 0, done.stderr
    listed = [p["profile"] for p in json.loads(done.stdout)["px4"]]
    assert listed == [*NAMES[:-1], NEXT, NAMES[-1]]
    made_up = {"profile": NEXT, "covers": f"v{NEXT}: made up by a test", "seen_running": []}
    assert made_up in json.loads(done.stdout)["px4"]


def test_a_new_record_judges_a_lint_with_the_rules_of_its_range() -> None:
    """``--px4 1.19.1`` selects the new record with no note; the rules the catalog gives to
    ``1.13+`` judge it, and its findings are those of the release it copies."""
    gap = str(CORPORA / "tlog" / "keepalive_gap_0_7s.tlog")
    done = _with_extra("lint", gap, "--px4", f"{NEXT}.1", "--format", "json")
    assert done.returncode in (0, 1), done.stderr
    assert "judged with profile" not in done.stderr
    (file,) = json.loads(done.stdout)["files"]
    assert file["profile"]["px4"] == NEXT
    copied = _with_extra("lint", gap, "--px4", NAMES[-2], "--format", "json")
    (same,) = json.loads(copied.stdout)["files"]
    codes = [f["code"] for f in file["findings"]]
    assert codes and codes == [f["code"] for f in same["findings"]]


# 1.18 beside main ----------------------------------------------------------------------------


def test_px4_1_18_is_its_own_profile_with_no_note() -> None:
    gap = str(CORPORA / "tlog" / "keepalive_gap_0_7s.tlog")
    result = run_cli(["lint", gap, "--px4", "1.18.0", "--format", "json"])
    assert json.loads(result.stdout)["files"][0]["profile"]["px4"] == "1.18"
    assert "judged with profile" not in result.stderr
    listed = [
        p["profile"] for p in json.loads(run_cli(["profiles", "--format", "json"]).stdout)["px4"]
    ]
    assert listed[-1] == "main" and listed.index("1.18") == listed.index("1.17") + 1


@pytest.mark.parametrize(
    "name", ["disarmed_switch_no_stream-1.18.0-alpha1.ulg", "acceleration_only-1.18.0-alpha1.tlog"]
)
def test_a_recording_of_px4_1_18_is_judged_with_profile_1_18(name: str) -> None:
    result = run_cli(["lint", str(CORPORA / "sitl" / name), "--format", "json"])
    (file,) = json.loads(result.stdout)["files"]
    assert file["profile"]["px4"] == "1.18" and file["profile"]["px4_source"] == "recording"


# main and 1.18 report the same version (gate spec 16) -----------------------------------------


def _lint_profile(path: str, *extra: str) -> dict[str, object]:
    (file,) = json.loads(run_cli(["lint", path, "--format", "json", *extra]).stdout)["files"]
    profile: dict[str, object] = file["profile"]
    return profile


@pytest.mark.parametrize(
    ("branch", "expected"), [("main", "main"), ("release/1.18", "1.18"), (None, "1.18")]
)
def test_a_ulog_of_px4_main_is_told_from_1_18_by_its_branch(
    tmp_path: Path, branch: str | None, expected: str
) -> None:
    from fuzzoff.formats.ulog.writer import write_ulog

    path = write_ulog(
        tmp_path / "flight.ulg", stream(0.0, 2.0), px4_version="1.18.0-beta", px4_branch=branch
    )
    profile = _lint_profile(str(path))
    assert profile["px4"] == expected and profile["px4_source"] == "recording"
    assert profile["px4_release"] == "1.18.0-beta"
    if branch is None:  # a build that names no branch: main reports the same version
        assert "main reports it too" in str(profile["px4_note"])
    else:
        assert "px4_note" not in profile


def test_a_tlog_reporting_1_18_is_judged_as_1_18_and_says_main_reports_the_same() -> None:
    profile = _lint_profile(str(CORPORA / "sitl" / "clean_offboard-1.18.0-alpha1.tlog"))
    assert profile["px4"] == "1.18"
    assert "--px4 main for a build of main" in str(profile["px4_note"])
    forced = _lint_profile(
        str(CORPORA / "sitl" / "clean_offboard-1.18.0-alpha1.tlog"), "--px4", "main"
    )
    assert forced["px4"] == "main" and "px4_note" not in forced


def test_main_and_1_18_are_two_records_main_written_as_what_main_changed() -> None:
    v118, main = releases.get("1.18"), releases.get("main")
    assert v118 != main
    changed = {
        f.name
        for f in dataclasses.fields(Release)
        if f.compare and getattr(v118, f.name) != getattr(main, f.name)
    }
    assert changed == {
        "name",
        "covers",
        "minors",
        "descend_sub_mode",
        "position_loss_action",
        "docs_say_2hz",
        "branches",
        "reports_as",
    }


def test_fuzzoff_profiles_says_which_releases_were_seen_running() -> None:
    listed = json.loads(run_cli(["profiles", "--format", "json"]).stdout)["px4"]
    seen = {p["profile"]: p["seen_running"] for p in listed}
    assert seen["1.18"][0] == "1.18.0-beta1-head" and seen["main"] == ["main-2026-08-13"]
    assert seen["1.17"][0] == "1.17.0" and seen["legacy"] == seen["1.13"] == []
    terminal = run_cli(["profiles"]).stdout
    assert "from the code only" in terminal and "1.18.0-beta1-head" in terminal


# mode numbering (gate spec 16 S10) --------------------------------------------------------------


@pytest.mark.parametrize("release", RELEASES, ids=NAMES)
def test_guided_course_and_descend_sub_modes_follow_the_record(release: Release) -> None:
    from fuzzoff.gate.requests import mode_request, switch_decision

    def asks(sub: int) -> Command:
        return Command(t=1.0, vehicle="1", command=176, params=(1.0, 4.0, float(sub), 0, 0, 0, 0))

    course, why = mode_request(asks(19), release)
    assert (course == 7) == release.guided_course_sub_mode
    assert course is not None or "AUTO sub-mode 19" in str(why)
    descend, why = mode_request(asks(20), release)
    assert descend is None and ("not selectable" in str(why)) == release.descend_sub_mode
    refused = switch_decision(release, asks(20), descend, True, True, 14)
    assert not refused.accepted


def test_a_heartbeat_in_guided_course_or_main_s_descend_is_named() -> None:
    from fuzzoff.modes import custom_mode_to_nav_state, nav_state_name

    assert nav_state_name(custom_mode_to_nav_state(4 << 16 | 19 << 24)) == "GUIDED_COURSE"
    assert nav_state_name(custom_mode_to_nav_state(4 << 16 | 20 << 24)) == "DESCEND"


@pytest.mark.parametrize(("px4", "own_docs"), [("1.17", True), ("1.18", False), ("main", True)])
def test_ofb101_says_which_docs_ask_for_2_hz(px4: str, own_docs: bool) -> None:
    """Gate spec 16 S12: the 1.18 docs give COM_OF_LOSS_T, main's say 2 Hz again."""
    path = str(CORPORA / "tlog" / "stream_lost_in_offboard.tlog")
    result = run_cli(["lint", path, "--px4", px4, "--format", "json"])
    (file,) = json.loads(result.stdout)["files"]
    (gap,) = [f for f in file["findings"] if f["code"] == "OFB101"][:1]
    assert ("docs: keep-alive at > 2 Hz" in gap["message"]) == own_docs
    assert ("1.18's give COM_OF_LOSS_T only" in gap["message"]) != own_docs


@pytest.mark.parametrize(
    ("name", "px4", "note"),
    [
        ("sticks_moved-main-2026-08-13.ulg", "main", False),  # ver_sw_branch main
        ("sticks_moved-1.18.0-beta1-head.ulg", "1.18", False),  # ver_sw_branch release/1.18
        ("sticks_moved-main-2026-08-13.tlog", "1.18", True),  # AUTOPILOT_VERSION only
    ],
)
def test_px4_s_own_recordings_of_main_and_the_1_18_head_pick_their_record(
    name: str, px4: str, note: bool
) -> None:
    profile = _lint_profile(str(CORPORA / "sitl" / name))
    assert profile["px4"] == px4 and profile["px4_source"] == "recording"
    assert ("px4_note" in profile) == note
