"""Issue 33: the other vehicles PX4 flies offboard, on the SITL bundles (no PX4 started here).

Which vehicle a run boots (``--vehicle``, ``PX4_SIM_MODEL``), which builds can fly it and why
not, and the recordings of each kept under 1 MB.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fuzzoff.sitl import airframes, bundle
from fuzzoff.sitl.scenarios import SCENARIOS, scenarios_for, vehicle_scenarios
from tests.helpers import run_cli

CORPORA = Path(__file__).resolve().parents[1] / "corpora"


def _bundle(root: Path, name: str, models: list[str], modules: list[str]) -> bundle.Build:
    folder = root / name
    (folder / "bin").mkdir(parents=True)
    (folder / "bin" / "px4").write_bytes(b"")
    (folder / "bin" / "commands.txt").write_text("".join(f"px4-{m}\n" for m in modules))
    frames = folder / "etc" / "init.d-posix" / "airframes"
    frames.mkdir(parents=True)
    for number, model in enumerate(models, 10040):
        (frames / f"{number}_{model}").write_text("")
    return bundle.Build(folder, name)


def test_a_vehicle_boots_its_sih_airframe_and_the_quad_changes_nothing(tmp_path: Path) -> None:
    build = _bundle(tmp_path, "1.17.0", ["sihsim_quadx", "sihsim_standard_vtol"], ["commander"])
    assert airframes.boot_env(build, "vtol") == {"PX4_SIM_MODEL": "sihsim_standard_vtol"}
    assert airframes.boot_env(build, "quad", {"PX4_SIM_SPEED_FACTOR": "2"}) == {
        "PX4_SIM_SPEED_FACTOR": "2"
    }


def test_the_airplane_boots_with_sihs_ground_at_sea_level(tmp_path: Path) -> None:
    # docs/sitl.md: TECS starts its altitude reference at 0 m AMSL before the estimator's
    # origin; SIH_LOC_H0 is read once when SIH starts, so it is a boot parameter
    build = _bundle(tmp_path, "1.17.0", ["sihsim_airplane"], ["commander"])
    assert airframes.boot_env(build, "fw") == {
        "PX4_SIM_MODEL": "sihsim_airplane",
        "PX4_PARAM_SIH_LOC_H0": "0",
    }
    assert (
        airframes.boot_env(build, "fw", {"PX4_PARAM_SIH_LOC_H0": "489.4"})["PX4_PARAM_SIH_LOC_H0"]
        == "489.4"
    )


def test_a_build_without_the_airframe_or_the_rover_module_says_why(tmp_path: Path) -> None:
    old = _bundle(tmp_path, "1.16.2", ["sihsim_quadx"], ["commander"])
    with pytest.raises(airframes.AirframeError, match="no SIH airframe sihsim_hex"):
        airframes.boot_env(old, "hex")
    plain = _bundle(tmp_path, "1.17.0", ["sihsim_rover_ackermann"], ["commander"])
    with pytest.raises(airframes.AirframeError, match="without the rover_ackermann module"):
        airframes.boot_env(plain, "rover-ackermann")
    rover = _bundle(tmp_path, "1.18.0-beta1-head", ["sihsim_rover_ackermann"], ["rover_ackermann"])
    assert airframes.boot_env(rover, "rover-ackermann")["PX4_SIM_MODEL"] == "sihsim_rover_ackermann"


def test_mains_rover_is_refused_with_the_reason(tmp_path: Path) -> None:
    main = _bundle(tmp_path, "main-2026-08-13", ["sihsim_rover_ackermann"], ["rover_ackermann"])
    with pytest.raises(airframes.AirframeError, match="stalls PX4's simulated clock"):
        airframes.boot_env(main, "rover-ackermann")


def test_sitl_run_names_an_unknown_vehicle_in_one_line() -> None:
    out = run_cli(["sitl", "run", "clean_offboard", "--release", "1.17.0", "--vehicle", "blimp"])
    assert out.returncode == 2
    assert "--vehicle blimp: no such SITL vehicle" in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


def test_sitl_list_shows_the_vehicles_and_their_airframes() -> None:
    out = run_cli(["sitl", "list"]).stdout
    assert "rover-ackermann" in out and "PX4_SIM_MODEL=sihsim_standard_vtol" in out
    assert "vtol_offboard" in out and "rover_loss" in out


def test_the_multicopter_matrix_keeps_its_scenarios_and_the_others_fly_their_vehicle() -> None:
    assert all(SCENARIOS[name].vehicle == "quad" for name in scenarios_for("1.16.2"))
    assert {SCENARIOS[name].vehicle for name in vehicle_scenarios()} == {
        "hex",
        "fw",
        "vtol",
        "tailsitter",
        "rover-ackermann",
    }


def test_the_airplane_and_the_tailsitter_fly_with_what_later_airframes_set() -> None:
    # docs/sitl.md: the 1.14/1.15 airplane arms only with its outputs where SIH reads them (the
    # 1.16 airframe's); it takes off on every bundle, with each one's fixes; the tailsitter's
    # transition waits for an airspeed SIH never shows unless FW_USE_AIRSPD is 0, and it climbs
    # only with the 1.18 airframe's right elevon
    params = SCENARIOS["fw_gate"].params
    assert [params[f"PWM_MAIN_FUNC{n}"] for n in range(1, 7)] == [201, 202, 203, 101, 0, 0]
    assert SCENARIOS["fw_gate"].flies_on is None
    assert SCENARIOS["fw_loss"].flies_on == (
        "1.14.4",
        "1.15.4",
        "1.16.2",
        "1.17.0",
        "1.18.0-alpha1",
        "1.18.0-beta1-head",
        "main-2026-08-13",
    )
    # 1.18's SIH pulls the airplane with SIH_F_T_MAX (2 N unless set), not the airframe's 6 N
    assert SCENARIOS["fw_loss"].params["SIH_F_T_MAX"] == 6.0
    assert "SIH_F_T_MAX" not in SCENARIOS["fw_gate"].params
    # 1.14's and 1.15's SIH pitch the other way and hold a grounded airplane level
    assert SCENARIOS["fw_loss"].params_for("1.15.4")["CA_SV_CS1_TRQ_P"] == -1.0
    assert SCENARIOS["fw_loss"].params_for("1.15.4")["FW_TKO_PITCH_MIN"] == 0.0
    assert "CA_SV_CS1_TRQ_P" not in SCENARIOS["fw_loss"].params_for("1.16.2")
    assert SCENARIOS["tailsitter_loss"].params["FW_USE_AIRSPD"] == 0.0
    assert SCENARIOS["tailsitter_loss"].params["CA_SV_CS1_TRQ_P"] == -0.5
    assert SCENARIOS["vtol_loss"].flies_on is None
    # the standard VTOL's transition on 1.16.2 ends back in MC (quad-chute): the programs
    # about FW flight are run where it reaches FW
    for name in ("vtol_fw_glide", "vtol_fw_types", "vtol_fw_takeoff_type", "vtol_fw_velocity"):
        flies_on = SCENARIOS[name].flies_on
        assert flies_on is not None and "1.16.2" not in flies_on and "1.17.0" in flies_on


def _verdict_of(stem: str) -> list[tuple[str, bool | None, str]]:
    from fuzzoff.sitl.verdict import compare

    runs = json.loads((SITL / "runs.json").read_text())
    run = runs[stem]
    verdict = compare(
        SITL / f"{stem}.tlog",
        run["release"].split("-")[0],
        SITL / f"{stem}.ulg",
        run.get("params") or {},
        245,
        airframes.airframe_for(run["vehicle"]).fuzzoff_vehicle,
    )
    return [(i.what, i.agree, i.note) for i in verdict.items]


def _fw_gate_stems() -> list[str]:
    return sorted(p.stem for p in (CORPORA / "sitl").glob("fw_gate-*.tlog"))


def test_the_airplanes_gate_is_recorded_on_every_bundle() -> None:
    # every bundle has sihsim_airplane (the SIH README): its ground run is on each of them
    assert len(_fw_gate_stems()) == 7


@pytest.mark.parametrize("stem", _fw_gate_stems())
def test_the_airplanes_gate_on_the_ground_judges_the_loss_and_its_action(stem: str) -> None:
    """fw_gate: armed in OFFBOARD on the ground, a 3 s stream stop: PX4 flags the loss, flies
    its failsafe action and returns to OFFBOARD; the model agrees on each, and on the disarm
    (refused while PX4 counts the rolling airplane as flying, then forced)."""
    items = _verdict_of(stem)
    judged = {what: agree for what, agree, _ in items if agree is not None}
    assert judged["loss time"] and judged["failsafe action"] and judged["automatic return"]
    assert not [i for i in items if i[1] is False]


def test_a_disarm_just_after_px4_counted_the_airplane_landed_is_not_judged_from_a_tlog() -> None:
    """fw_gate on 1.18.0-alpha1: PX4's land detector said landed 72 ms before the disarm; the
    tlog's EXTENDED_SYS_STATE (5 Hz) still said in the air, so the model refused the disarm PX4
    took. The verdict says why it cannot judge it instead of calling it a disagreement."""
    (disarm,) = [i for i in _verdict_of("fw_gate-1.18.0-alpha1") if i[0] == "disarm"]
    assert disarm[1] is None
    assert "land detector said landed 72 ms before the disarm" in disarm[2]


def test_a_land_verdict_older_than_one_sample_period_is_judged() -> None:
    from fuzzoff.sitl.truth import Truth
    from fuzzoff.sitl.verdict import _land_sample_lag

    truth = Truth(landed=[(0.0, True), (5.0, False), (9.9, True)])
    refused = {"what": "disarm_rejected", "message": "land detector: not landed since 5.00 s"}
    assert "100 ms before the disarm" in _land_sample_lag(truth, 10.0, "disarm", refused)
    assert _land_sample_lag(truth, 10.5, "disarm", refused) == ""
    assert _land_sample_lag(truth, 10.0, "arm", refused) == ""
    assert _land_sample_lag(Truth(), 10.0, "disarm", refused) == ""


def test_a_land_verdict_px4_published_between_the_disarm_and_its_answer_is_not_judged() -> None:
    """fw_ground_gate over the ROS 2 bridge on main-2026-08-13 (a live run, not kept): PX4 took
    the plain disarm, its land detector counting the rolling airplane landed in the Commander
    cycle between the disarm's stamp and the answer; the bag had no such sample when the node
    sent it, so the model refused it. That is not judged, saying why."""
    from fuzzoff.sitl.truth import Truth
    from fuzzoff.sitl.verdict import _land_sample_lag

    truth = Truth(landed=[(0.0, True), (13.46, False), (16.64, True)])
    refused = {"what": "disarm_rejected", "message": "land detector: not landed since 7.38 s"}
    note = _land_sample_lag(truth, 16.628, "disarm", refused)
    assert "said landed 12 ms after the disarm's stamp, before PX4 answered it" in note
    assert _land_sample_lag(truth, 16.5, "disarm", refused) == ""  # 140 ms before: judged


def test_thinning_cuts_the_fast_topics_and_keeps_the_stream_whole(tmp_path: Path) -> None:
    from pyulog import ULog

    from fuzzoff.sitl.trim import trim

    source = CORPORA / "sitl" / "hold_with_unknown_sub_mode-1.18.0-beta1-head.ulg"
    thin = trim(source, tmp_path / "thin.ulg", thin_s=0.1)

    def counts(path: Path) -> dict[str, int]:
        return {d.name: len(d.data["timestamp"]) for d in ULog(str(path)).data_list}

    before, after = counts(source), counts(thin)
    assert after["offboard_control_mode"] == before["offboard_control_mode"]
    assert after["trajectory_setpoint"] == before["trajectory_setpoint"]
    assert after["vehicle_local_position"] < before["vehicle_local_position"] / 5
    assert thin.stat().st_size < source.stat().st_size
    lint = run_cli(["lint", str(thin), "--format", "json"])
    assert lint.returncode == run_cli(["lint", str(source), "--format", "json"]).returncode


SITL = CORPORA / "sitl"


def _phases(path: Path) -> list[str]:
    """The VTOL phases a recording's statuses go through, in order, each once per stretch."""
    from fuzzoff.events import VehicleStatus
    from fuzzoff.formats import open_source

    seen: list[str] = []
    with open_source(path) as source:
        for event in source.events():
            phase = event.vtol_phase if isinstance(event, VehicleStatus) else None
            if phase is not None and (not seen or seen[-1] != phase):
                seen.append(phase)
    return seen


@pytest.mark.parametrize("suffix", [".ulg", ".tlog"])
def test_a_real_vtols_phase_is_read_at_each_moment(suffix: str) -> None:
    """PX4 1.17's standard VTOL: MC takeoff, transition to FW in OFFBOARD and back (ULog
    vehicle_status, tlog EXTENDED_SYS_STATE.vtol_state)."""
    phases = _phases(SITL / f"vtol_offboard-1.17.0{suffix}")
    assert phases == ["mc", "transition", "fw", "transition", "mc"]


def test_px4s_own_transition_setpoints_are_not_the_clients() -> None:
    """During a transition PX4's transition flight task writes trajectory_setpoint (velocity)
    in OFFBOARD: the ULog of a clean VTOL flight on position setpoints has no OFB401."""
    out = run_cli(["lint", str(SITL / "vtol_offboard-1.17.0.ulg"), "--format", "json"])
    codes = {f["code"] for f in json.loads(out.stdout)["files"][0]["findings"]}
    assert "OFB401" not in codes
    assert out.returncode == 0


def test_a_rovers_tlog_says_rover_but_not_which_kind_and_its_ulog_says_ackermann() -> None:
    """PX4 sends HEARTBEAT type 10 for every rover: the tlog's kind is assumed and said
    (OFB003); the ULog's rover topics tell the Ackermann drive."""
    tlog = run_cli(
        ["lint", str(SITL / "rover_offboard-1.18.0-beta1-head.tlog"), "--format", "json"]
    )
    (report,) = json.loads(tlog.stdout)["files"]
    assumed = [f for f in report["findings"] if f["code"] == "OFB003"]
    assert assumed and "not which kind" in assumed[0]["message"]
    ulog = run_cli(["lint", str(SITL / "rover_offboard-1.18.0-beta1-head.ulg")])
    assert "rover-ackermann detected" in ulog.stdout


@pytest.mark.parametrize(
    ("stem", "vehicle"),
    [
        ("hex_offboard-1.17.0", "mc detected"),
        ("hex_offboard-1.18.0-beta1-head", "mc detected"),
        ("vtol_offboard-1.18.0-beta1-head", "vtol detected"),
    ],
)
def test_each_real_vehicle_is_detected_from_its_recordings(stem: str, vehicle: str) -> None:
    for suffix in (".tlog", ".ulg"):
        out = run_cli(["lint", str(SITL / f"{stem}{suffix}")])
        assert vehicle in out.stdout.splitlines()[0]


@pytest.mark.parametrize(
    "stem",
    [
        "vtol_fw_glide-1.18.0-beta1-head",
        "vtol_fw_types-1.18.0-beta1-head",
        "vtol_fw_types-main-2026-08-13",
        "vtol_fw_types-1.17.0",
    ],
)
def test_a_vtol_on_a_nan_altitude_in_fw_flight_is_not_a_copter_hold(stem: str) -> None:
    """The standard VTOL in FW flight on position setpoints with z NaN: the 1.18 head glided
    (down 14-29 m, climbing back when z came again), 1.17.0 flew on at its altitude toward
    x, y. Neither held as a multicopter does: OFB602's multicopter axis check ("PX4 holds
    instead") does not apply in FW flight on any release."""
    tlog = SITL / f"{stem}.tlog"
    out = run_cli(["lint", str(tlog), "--format", "json"])
    codes = {f["code"] for f in json.loads(out.stdout)["files"][0]["findings"]}
    assert "OFB602" not in codes
    assert out.returncode == 0


@pytest.mark.parametrize(
    ("name", "vehicle"),
    [("fw", "fw"), ("plane", "fw"), ("mc", "quad"), ("hex", "hex"), ("vtol", "vtol")],
)
def test_a_live_campaign_takes_a_sitl_vehicle_or_a_vehicle_type(name: str, vehicle: str) -> None:
    assert airframes.airframe_named(name).vehicle == vehicle


def test_a_live_campaign_on_a_build_without_the_airframe_says_so_in_one_line(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    _bundle(tmp_path, "1.16.2", ["sihsim_quadx", "sihsim_airplane"], ["commander"])
    monkeypatch.setenv("FUZZOFF_PX4_SITL", str(tmp_path))
    out = run_cli(["fuzz", "--against", "sitl:1.16.2", "--vehicle", "hex"], cwd=tmp_path)
    assert out.returncode == 2
    assert "--vehicle hex: PX4 1.16.2 has no SIH airframe sihsim_hex" in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


def test_an_instance_above_nine_is_listened_for_where_px4_sends_it() -> None:
    # px4-rc.mavlink of every bundle: above 9, the onboard link sends to 14549
    assert bundle.send_port(3) == 14543
    assert bundle.send_port(30) == bundle.send_port(31) == 14549


def test_the_tailsitters_runs_agree_with_the_model_beside_a_parameter_it_does_not_read() -> None:
    """tailsitter_loss sets FW_USE_AIRSPD 0 (not a gate parameter): the verdict leaves it out
    and the model agrees with PX4 on both losses, in MC and in FW flight."""
    from fuzzoff.sitl.verdict import compare

    stem = "tailsitter_loss-1.18.0-beta1-head"
    verdict = compare(
        SITL / f"{stem}.tlog",
        "1.18",
        SITL / f"{stem}.ulg",
        SCENARIOS["tailsitter_loss"].params,
        245,
        "vtol",
    )
    losses = [i for i in verdict.items if i.what == "failsafe action"]
    assert len(losses) == 2
    assert all(i.agree for i in verdict.items)


def test_a_parameter_is_set_under_its_old_name_on_a_px4_that_predates_it() -> None:
    """1.14.4 has FW_ARSP_MODE (1: airspeed not used) where 1.15 and later have FW_USE_AIRSPD
    (0: not used): the tailsitter's runs set whichever PX4 has. Before 1.18 SIH's airplane
    takes its thrust from SIH_T_MAX, which 1.18 split off into SIH_F_T_MAX."""
    from typing import cast

    from fuzzoff.sitl.link import Link, LinkError
    from fuzzoff.sitl.session import apply_params

    class FakeLink:
        def __init__(self, names: set[str]) -> None:
            self.values = dict.fromkeys(names, -1.0)

        def set_param(self, name: str, value: float) -> float:
            if name not in self.values:
                raise LinkError(f"PX4 has no parameter {name} (no PARAM_VALUE for it)")
            self.values[name] = value
            return value

    old = FakeLink({"FW_ARSP_MODE", "CA_SV_CS1_TRQ_P", "SIH_T_MAX"})
    params = {"FW_USE_AIRSPD": 0.0, "CA_SV_CS1_TRQ_P": -0.5, "SIH_F_T_MAX": 6.0}
    applied = apply_params(cast(Link, old), params)
    assert applied == {"FW_ARSP_MODE": 1.0, "CA_SV_CS1_TRQ_P": -0.5, "SIH_T_MAX": 6.0}
    new = FakeLink({"FW_USE_AIRSPD", "CA_SV_CS1_TRQ_P", "SIH_F_T_MAX"})
    assert apply_params(cast(Link, new), params) == params


@pytest.mark.parametrize(
    ("vehicle", "fixed"),
    [("fw", "PWM_MAIN_FUNC4"), ("tailsitter", "CA_SV_CS1_TRQ_P"), ("quad", None)],
)
def test_a_live_campaign_boots_the_airframe_with_the_scenarios_fixes(
    tmp_path: Path, vehicle: str, fixed: str | None
) -> None:
    """A campaign on the airplane or the tailsitter sets what their scenarios set (the 1.14/1.15
    airplane's outputs, elevator and lift-off, the 1.18 airplane's thrust, the tailsitter's
    airspeed use and elevon) at each boot of PX4."""
    from fuzzoff.sitl.against import AgainstConfig, Campaign

    build = _bundle(
        tmp_path, "1.14.4", ["sihsim_quadx", "sihsim_airplane", "sihsim_xvert"], ["commander"]
    )
    campaign = Campaign(AgainstConfig(build=build, vehicle=vehicle), log=lambda line: None)
    try:
        fixes = campaign.bench.fixes
    finally:
        campaign.bench.close()
    if fixed is None:
        assert fixes == {}
    else:
        scenario = "fw_loss" if vehicle == "fw" else "tailsitter_loss"
        assert fixed in fixes and fixes == SCENARIOS[scenario].params_for(build.release)


def _trajectory_between(stem: str, start: str, end: str) -> list[tuple[float, ...]]:
    """PX4's trajectory_setpoint (x, y, z, vx, vy, vz) between two steps of the run, PX4's
    time (the ULog keeps the setpoint topics whole)."""
    from pyulog import ULog

    runs = json.loads((SITL / "runs.json").read_text())
    steps = {s["what"]: s["px4_t"] for s in runs[stem]["steps"]}
    (data,) = [d.data for d in ULog(str(SITL / f"{stem}.ulg"), ["trajectory_setpoint"]).data_list]
    fields = [f"position[{i}]" for i in range(3)] + [f"velocity[{i}]" for i in range(3)]
    return [
        tuple(float(data[f][i]) for f in fields)
        for i, t in enumerate(data["timestamp"] / 1e6)
        if steps[start] + 0.5 < t < steps[end] - 0.3
    ]


@pytest.mark.parametrize(
    "stem", ["vtol_fw_takeoff_type-1.17.0", "vtol_fw_takeoff_type-1.18.0-beta1-head"]
)
def test_the_takeoff_setpoint_type_in_fw_flight_reaches_px4_as_a_plain_position(stem: str) -> None:
    """type_mask 4096 clears every ignore bit and PX4's receiver (1.12+) reads no type bits:
    PX4's trajectory_setpoint is the position with zero velocity, and the VTOL flew on to it
    at its altitude (docs/sitl.md). Nothing in it is a hazard for lint."""
    assert SCENARIOS["vtol_fw_takeoff_type"].kind == "clean"
    setpoints = set(
        _trajectory_between(stem, "type_mask 4096 (takeoff)", "position setpoint again")
    )
    assert setpoints == {(400.0, 0.0, -30.0, 0.0, 0.0, 0.0)}
    assert run_cli(["lint", str(SITL / f"{stem}.tlog")]).returncode == 0


@pytest.mark.parametrize("stem", ["fw_takeoff_type-1.16.2", "fw_takeoff_type-1.17.0"])
def test_the_airplanes_takeoff_type_on_the_ground_is_flown_as_a_position(stem: str) -> None:
    """fw_takeoff_type: 4096 200 m ahead and 30 m up, armed in OFFBOARD on the ground. PX4
    reads no type bits: the setpoint is a position with zero velocity (path following), not a
    runway takeoff; the disarm is refused (PX4 counts the airplane as flying) and forced."""
    scenario = SCENARIOS["fw_takeoff_type"]
    assert scenario.params == SCENARIOS["fw_gate"].params
    assert scenario.flies_on == ("1.16.2", "1.17.0", "1.18.0-beta1-head")
    setpoints = set(_trajectory_between(stem, "arm", "disarm"))
    assert setpoints == {(200.0, 0.0, -30.0, 0.0, 0.0, 0.0)}
    steps = json.loads((SITL / "runs.json").read_text())[stem]["steps"]
    assert [(s["what"], s["result"]) for s in steps][-2:] == [
        ("disarm", 1),
        ("disarm (forced)", 0),
    ]


@pytest.mark.parametrize("stem", ["vtol_fw_velocity-1.17.0", "vtol_fw_velocity-1.18.0-beta1-head"])
def test_a_velocity_only_setpoint_in_fw_flight_gives_ofb604(stem: str) -> None:
    """The standard VTOL in FW flight on 10 m/s east without a position: PX4 did not turn to
    it (docs/sitl.md). OFB604 judges a VTOL's setpoints in FW flight by the docs' fixed-wing
    table, an error where the message has no position; not in MC flight."""
    out = run_cli(["lint", str(SITL / f"{stem}.tlog"), "--format", "json"])
    found = [f for f in json.loads(out.stdout)["files"][0]["findings"] if f["code"] == "OFB604"]
    assert [f["severity"] for f in found] == ["error"]
    assert "VTOL in FW flight" in found[0]["message"] and "vy" in found[0]["message"]
    assert out.returncode == 1
    assert SCENARIOS["vtol_fw_velocity"].codes == ("OFB604",)
