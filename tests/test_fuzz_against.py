"""``fuzzoff fuzz --against sitl:RELEASE`` without a running PX4: its options, how it tells PX4
behaviour from noise and from the vehicle's own failsafes, how it shrinks a disagreement, and
the reproducer it saves. The live campaign itself runs in ``test_sitl_live.py``."""

from __future__ import annotations

import itertools
import json
import os
from pathlib import Path

import pytest

os.environ.setdefault("MAVLINK20", "1")

from fuzzoff import events as ev
from fuzzoff.fuzz import recordings
from fuzzoff.fuzz.reproducers import load
from fuzzoff.fuzz.scenario import AUTOPILOT, COMPANION, Scenario
from fuzzoff.fuzz.strategies import CommandPlan
from fuzzoff.fuzz.streams import commands, echo, settle
from fuzzoff.sitl import bundle, delivery
from fuzzoff.sitl.against import AgainstConfig, Campaign, Disagreement, Example, with_start
from fuzzoff.sitl.classify import edge_note, health_refusals, own_changes, shape, signature
from fuzzoff.sitl.driver import NAV_LOITER
from fuzzoff.sitl.link import COMPANION_SYSID
from fuzzoff.sitl.replay import plan_from_tlog
from fuzzoff.sitl.truth import Mode, Request, Truth, read_truth
from fuzzoff.sitl.variants import variants
from fuzzoff.sitl.verdict import Item, Verdict, compare
from tests.helpers import CORPORA, run_cli

NAV_POSCTL, NAV_OFFBOARD = 2, 14


def _setpoint(t: float, frame: int = 1, mask: int = 0x0DF8) -> ev.SetPositionTargetLocal:
    return ev.SetPositionTargetLocal(
        t=t,
        vehicle="1",
        sender_time_us=round(t * 1000) * 1000,
        target_system=AUTOPILOT[0],
        target_component=AUTOPILOT[1],
        source_system=COMPANION[0],
        source_component=COMPANION[1],
        coordinate_frame=frame,
        type_mask=mask,
        position=(1.0, 2.0, -3.0),
    )


def _stream(
    times: list[float],
    plan: CommandPlan,
    params: dict[str, float] | None = None,
    mask: int = 0x0DF8,
) -> Scenario:
    """A MAVLink stream as the campaign draws them: setpoints, the plan's commands, the
    model's acks."""
    params = params or {}
    sent = settle([*(_setpoint(t, mask=mask) for t in times), *commands(plan, "mavlink")])
    answers = echo(sent, "1.15", "mc", params, acks=True, status=False, transport="mavlink")
    return Scenario("1.15", "mc", "mavlink", tuple(settle([*sent, *answers])), params)


TEN_HZ = [round(0.1 * i, 4) for i in range(20)] + [round(3.2 + 0.1 * i, 4) for i in range(10)]
"""2 s at 10 Hz, a 1.3 s stall, 1 s more."""
PLAN = CommandPlan(arm=0.5, switch=1.0, leave=None, disarm=None)


# ------------------------------------------------------------------------- the command line


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["--against", "gazebo:1.15"], "expected sitl:RELEASE"),
        (["--against", "sitl"], "expected sitl:RELEASE"),
        (["--against", "sitl:9.9"], "no such bundle"),
        (["--against", "sitl:1.15", "--from", "x.tlog"], "--from does not go with --against"),
        (["--against", "sitl:1.15", "--px4", "1.16"], "--px4 (the release is the one of"),
        (["--against", "sitl:1.15", "--vehicle", "rover"], "no SIH airframe flies it"),
        (["--against", "sitl:1.15", "--vehicle", "boat"], "no SIH airframe flies it"),
        (["--against", "sitl:1.15", "--format", "sarif"], "terminal or json"),
        (["--against", "sitl:1.15", "--instance", "100"], "expected 0 to 99"),
        (["--against", "sitl:1.15", "--budget", "0"], "above 0"),
        (["--px4-build", "."], "--px4-build goes with --against"),
    ],
)
def test_a_live_campaign_names_a_wrong_option_in_one_line(
    args: list[str], says: str, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    # bundles present or not, the options are checked first (sitl:9.9 needs the folder)
    root = bundle.default_root() if "sitl:9.9" in args else tmp_path
    monkeypatch.setenv("FUZZOFF_PX4_SITL", str(root))
    out = run_cli(["fuzz", *args], cwd=tmp_path)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and says in lines[0], out.stderr
    assert not (tmp_path / ".fuzzoff").exists()


def test_a_live_campaign_without_the_bundles_says_where_it_looked(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setenv("FUZZOFF_PX4_SITL", str(tmp_path / "nowhere"))
    out = run_cli(["fuzz", "--against", "sitl:1.15", "--budget", "60"], cwd=tmp_path)
    assert out.returncode == 2
    assert "no PX4 SITL bundles in" in out.stderr and "nowhere" in out.stderr
    assert "FUZZOFF_PX4_SITL" in out.stderr


# ------------------------------------------------------------------------- noise


def test_a_stream_sent_as_meant_is_faithful() -> None:
    meant = [0.0, 0.1, 0.2, 1.5, 1.6]
    sent = [100.0 + t + 0.004 * (i % 2) for i, t in enumerate(meant)]
    report = delivery.check(meant, sent)
    assert report.faithful
    assert report.worst_s == pytest.approx(0.004, abs=1e-9)


def test_a_gap_the_host_stretched_is_noise_and_says_where() -> None:
    """1.0 s meant, 1.03 s sent (a busy host): PX4's answer to it is not the stream's."""
    meant = [0.0, 0.1, 1.1, 1.2]
    sent = [50.0, 50.1, 51.13, 51.23]
    report = delivery.check(meant, sent)
    assert not report.faithful
    assert report.at_s == pytest.approx(1.1)
    assert report.worst_s == pytest.approx(0.03, abs=1e-9)
    assert "30 ms off at 1.100 s" in report.describe()


# ------------------------------------------------------------------------- PX4 by itself


def test_a_disarm_no_command_and_no_loss_explains_is_the_vehicles_own() -> None:
    """A flipped vehicle: PX4's failure detector disarms it (outside the gate)."""
    truth = Truth(
        requests=[Request(10.0, 400, 1.0, 0.0, 0.0, 0), Request(10.0, 176, 1.0, 6.0, 0.0, 0)],
        modes=[
            Mode(9.0, NAV_LOITER, False, None),
            Mode(10.01, NAV_LOITER, True, None),
            Mode(10.02, NAV_OFFBOARD, True, None),
            Mode(13.4, NAV_OFFBOARD, False, None),
        ],
        loss_flag=[(9.0, True), (10.01, False)],
        texts=[
            (13.39, "[health_and_arming_checks] Preflight Fail: Attitude failure (roll)"),
            (13.4, "[tone_alarm] notify neutral"),
            (13.4, "[commander] Disarmed by failsafe"),
        ],
    )
    (change,) = own_changes(truth, since=9.5)
    assert change.what == "disarmed" and change.t == 13.4
    assert "Attitude failure (roll)" in change.describe()
    assert "tone_alarm" not in change.describe()


def test_a_failsafe_after_the_loss_flag_is_not_the_vehicles_own() -> None:
    truth = Truth(
        requests=[Request(10.0, 176, 1.0, 6.0, 0.0, 0)],
        modes=[
            Mode(9.0, NAV_LOITER, True, None),
            Mode(10.02, NAV_OFFBOARD, True, None),
            Mode(12.11, NAV_POSCTL, True, None),
        ],
        loss_flag=[(10.01, False), (12.1, True)],
    )
    assert own_changes(truth, since=9.5) == []


def test_a_loss_on_a_gap_within_one_check_of_the_timeout_is_at_the_edge() -> None:
    edge = _stream([0.0, 0.1, 0.2, 1.25, 1.35], PLAN)
    assert edge_note(edge) is not None and "1.050 s" in edge_note(edge)  # type: ignore[operator]
    clear = _stream([0.0, 0.1, 0.2, 1.6, 1.7], PLAN)
    assert edge_note(clear) is None


# ------------------------------------------------------------------------- the same disagreement


def _item(t: float, px4: str, model: str, what: str = "arm") -> Item:
    return Item(what, t, px4, model, False)


def test_a_disagreement_is_the_same_at_another_time() -> None:
    first = _item(12.3, "rejected (1)", "accepted: armed")
    again = _item(40.9, "rejected (1)", "accepted: armed")
    other = _item(12.3, "accepted", "rejected: no offboard signal")
    assert signature(first) == signature(again) != signature(other)
    loss_a = _item(5.0, "1.036 s after the newest keep-alive", "1.151 s; window", "loss time")
    loss_b = _item(9.0, "1.012 s after the newest keep-alive", "1.140 s; window", "loss time")
    assert signature(loss_a) == signature(loss_b)


def test_streams_the_gate_cannot_tell_apart_are_sent_once() -> None:
    a = _stream(TEN_HZ, PLAN)
    jittered = _stream([t + 0.003 for t in TEN_HZ], PLAN)
    later_switch = _stream(TEN_HZ, CommandPlan(arm=0.5, switch=1.6, leave=None, disarm=None))
    shorter_loss = _stream(TEN_HZ, PLAN, {"COM_OF_LOSS_T": 0.5})
    assert shape(a) == shape(jittered)
    assert len({shape(a), shape(later_switch), shape(shorter_loss)}) == 3


# ------------------------------------------------------------------------- shrinking


def test_simpler_variants_come_in_order_and_keep_what_the_disagreement_needs() -> None:
    stream = _stream(TEN_HZ, CommandPlan(arm=0.5, switch=1.0, leave=3.5, disarm=0.7), mask=0x0DC7)
    found = list(variants(stream, t=3.0))
    names = [name for name, _ in found]
    assert names[0] == "cut after 3.20 s"
    assert names[1] == "plain setpoints"
    assert names[2:] == [
        "without the disarm at 0.70 s",
        "without the arm at 0.50 s",
        "without the switch at 1.00 s",
    ]
    cut = found[0][1]
    assert cut.events[-1].t <= 3.2 + 0.01
    assert not any(isinstance(e, ev.Command) and e.t > 3.2 for e in cut.events)
    plain = found[1][1]
    targets = [e for e in plain.events if isinstance(e, ev.MavlinkTarget)]
    assert {(e.type_mask, e.position) for e in targets} == {(0x0DF8, (0.0, 0.0, -2.5))}
    no_disarm = found[2][1]
    # the model's acks answer the variant's own commands
    acks = [e for e in no_disarm.events if isinstance(e, ev.CommandAck)]
    sent = [e for e in no_disarm.events if isinstance(e, ev.Command)]
    assert len(acks) == len(sent) == 3


def test_thinning_keeps_every_gap_the_loss_timeout_is_about() -> None:
    fast = [round(0.02 * i, 4) for i in range(60)] + [round(2.5 + 0.02 * i, 4) for i in range(20)]
    stream = _stream(fast, PLAN)
    thinned = dict(variants(stream, t=5.0))["thinned to 10 Hz"]
    times = [e.t for e in thinned.events if isinstance(e, ev.MavlinkTarget)]
    assert len(times) < len(fast) / 3
    assert max(b - a for a, b in itertools.pairwise(times)) == pytest.approx(2.5 - 1.18, abs=1e-6)


# ------------------------------------------------------------------------- the stream sent


def test_the_stream_sent_starts_where_the_bench_puts_px4(tmp_path: Path) -> None:
    """What the campaign sends is what replay --to of its reproducer sends: the companion's
    messages from the tlog writer, after PX4's HEARTBEAT saying disarmed in Hold."""
    stream = _stream(TEN_HZ, PLAN)
    path = recordings.write(with_start(stream), tmp_path / "s.tlog", "tlog")
    plan = plan_from_tlog(path)
    assert plan.start_text() == "AUTO_LOITER disarmed"
    sent = [e for e in stream.events if isinstance(e, ev.Command | ev.MavlinkTarget)]
    assert len(plan.messages) == len(sent)
    assert {m.get_srcSystem() for _, m in plan.messages} == {COMPANION[0]}
    assert plan.messages[0][0] == 0.0
    assert plan.messages[-1][0] == pytest.approx(sent[-1].t - sent[0].t, abs=1e-3)


# ------------------------------------------------------------------------- the reproducer


def test_a_disagreement_is_saved_as_a_reproducer_replay_reads(tmp_path: Path) -> None:
    stream = _stream(TEN_HZ, PLAN, {"COM_OF_LOSS_T": 0.5, "FUZZOFF_RC_PRESENT": 0.0})
    exchange = tmp_path / "run.px4.tlog"
    exchange.write_bytes(b"")
    item = _item(107.2, "rejected (1)", "accepted: armed")
    verdict = Verdict("1.15.4", "ulog", [item])
    found = Example(3, stream, "differ", verdict=verdict, tlog=exchange)
    case = Disagreement(found, True, found, ["cut after 1.20 s"], 2)
    config = AgainstConfig(
        build=bundle.Build(tmp_path, "1.15.4"), instance=1, save_dir=tmp_path / "out"
    )
    campaign = Campaign(config, log=lambda line: None)
    try:
        campaign._save(case)
    finally:
        campaign.bench.close()
    assert case.reproducer is not None
    name = case.reproducer.name.removesuffix(".expected.json")
    assert name.startswith("px4-1.15-mc-mavlink-")
    spec = json.loads(case.reproducer.read_text())
    assert spec["property"] is None
    assert spec["setup"]["params"] == {"COM_OF_LOSS_T": 0.5}
    assert spec["setup"]["manual_control"] is False
    against = spec["against"]
    assert against["px4"] == "1.15.4" and against["confirmed"] is True
    assert against["differ"][0]["px4"] == "rejected (1)"
    assert against["shrunk_by"] == ["cut after 1.20 s"]
    assert against["exchange_tlog"] == f"{name}.px4.tlog"
    assert "--to udp:127.0.0.1:14581" in against["replay"]
    reproducer = load(case.reproducer)
    assert reproducer.prop is None
    assert reproducer.setup is not None and reproducer.setup.params == {"COM_OF_LOSS_T": 0.5}
    out = run_cli(["replay", str(case.reproducer)])
    assert out.returncode == 0, out.stdout + out.stderr
    assert "findings: as expected" in out.stdout
    assert "against PX4 1.15.4 (confirmed): it and the model differed" in out.stdout
    assert "arm: PX4 rejected (1); model accepted: armed" in out.stdout
    assert "--to udp:127.0.0.1:14580" in out.stdout


def test_replay_to_sends_the_setups_parameters_and_a_joystick(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A reproducer that assumed manual control and COM_OF_LOSS_T 0.5: PX4 gets that parameter
    (not fuzzoff's own FUZZOFF_RC_PRESENT, which it does not have) and a MAVLink joystick."""
    from fuzzoff.fuzz.reproducers import save

    stream = _stream(TEN_HZ, PLAN, {"COM_OF_LOSS_T": 0.5, "FUZZOFF_RC_PRESENT": 1.0})
    path = save("explained", stream, [], tmp_path)
    seen: dict[str, object] = {}

    def fake(recording: Path, target: object, tlog: Path, **kwargs: object) -> object:
        seen.update(kwargs, recording=recording)
        raise OSError("stop here")

    monkeypatch.setattr("fuzzoff.sitl.run.replay_live", fake)
    out = run_cli(["replay", str(path), "--to", "udp:127.0.0.1:9"])
    assert out.returncode == 2 and "stop here" in out.stderr
    assert seen["params"] == {"COM_OF_LOSS_T": 0.5}
    assert seen["manual"] is True


# ---------------------------------------------------------------- the verdict, on live runs

EXCHANGES = CORPORA / "against" / "exchanges"


def _judge(stem: str, params: dict[str, float]) -> Verdict:
    release = stem.split("-", 1)[1]
    tlog, ulog = EXCHANGES / f"{stem}.tlog", EXCHANGES / f"{stem}.ulg"
    return compare(tlog, release, ulog, params, COMPANION_SYSID)


def test_an_arm_a_switch_and_a_disarm_sent_together_are_each_judged_on_their_own() -> None:
    """PX4 1.15.4 armed, refused the switch (no stream yet) and disarmed, 0.1 ms apart, as
    the model says; the verdict paired the arm with the switch's rejection before."""
    verdict = _judge("arm_switch_disarm_same_ms-1.15.4", {"COM_OF_LOSS_T": 1.0})
    judged = {(i.what, i.px4, i.model.split(":")[0]) for i in verdict.items if i.agree}
    assert judged == {
        ("arm", "accepted", "accepted"),
        ("switch to OFFBOARD", "rejected (1)", "rejected"),
        ("disarm", "accepted", "accepted"),
    }
    assert verdict.agree


def test_a_loss_action_that_disarms_is_judged_as_a_disarm() -> None:
    """COM_OBL_RC_ACT 7 on PX4 1.16.2: PX4 disarms and stays in OFFBOARD's nav state."""
    verdict = _judge("loss_action_disarm-1.16.2", {"COM_OF_LOSS_T": 1.0, "COM_OBL_RC_ACT": 7.0})
    (action,) = [i for i in verdict.items if i.what == "failsafe action"]
    assert action.px4 == "disarmed" and action.model.startswith("disarmed:")
    assert verdict.agree


def test_losses_a_few_tenths_apart_are_each_paired_with_the_models_nearest() -> None:
    """COM_OF_LOSS_T 0.2 and a jittered 5 Hz stream on PX4 1.15.4: PX4 ran four losses; the
    model two of them at the same checks, and missed two whose keep-alive came back 6 ms
    after its own check (33 ms after PX4's): the check's phase."""
    verdict = _judge("losses_0_2s_apart-1.15.4", {"COM_OF_LOSS_T": 0.2, "COM_OBL_RC_ACT": 5.0})
    timed = [i for i in verdict.items if i.what == "loss time"]
    assert len(timed) == 2 and all(i.agree for i in timed)
    assert all(i.px4.startswith("0.2") for i in timed)  # after the keep-alive before the flag
    missed = [i for i in verdict.items if i.what == "offboard loss"]
    assert [(i.px4, i.model) for i in missed] == [("lost", "no loss predicted")] * 2


def test_an_arm_px4_refused_for_its_own_health_checks_is_outside_the_gate() -> None:
    """A live 1.15.4 campaign: PX4 refused an arm 0.9 s after 'Preflight Fail: horizontal
    velocity unstable' (its estimator after the previous stream's landing); the model, which
    knows nothing of health checks, accepted it. Named as PX4's own refusal, so the campaign
    counts it outside the gate; the gate's own refusal (an arm in OFFBOARD with no stream,
    'Arming denied: Resolve system health failures first' alone) is not."""
    verdict = _judge("arm_refused_health-1.15.4", {"COM_OF_LOSS_T": 0.2})
    (arm,) = [i for i in verdict.items if i.what == "arm"]
    assert (arm.px4, arm.agree) == ("rejected (1)", False)
    (own,) = health_refusals(read_truth(EXCHANGES / "arm_refused_health-1.15.4.ulg"), 0.0)
    assert own.t == pytest.approx(arm.t, abs=0.01)
    assert "horizontal velocity unstable" in own.describe()
    for release in ("1.15.4", "1.16.2", "1.17.0"):
        gate_refusal = read_truth(CORPORA / "sitl" / f"disarmed_switch_no_stream-{release}.ulg")
        assert health_refusals(gate_refusal, 0.0) == []


def test_an_arm_in_position_without_manual_control_is_refused_as_px4_refused_it() -> None:
    """A confirmed disagreement of a live 1.18.0-alpha1 campaign (seen in four streams): a
    switch to Position with no joystick, then an arm, which PX4 refused (Position needs manual
    control) and the model accepted. The model now refuses it too."""
    params = {"COM_OF_LOSS_T": 0.19, "COM_OBL_RC_ACT": 4.0, "FUZZOFF_RC_PRESENT": 0.0}
    verdict = _judge("arm_posctl_no_manual-1.18.0-alpha1", params)
    (arm,) = [i for i in verdict.items if i.what == "arm"]
    assert (arm.px4, arm.agree) == ("rejected (1)", True)
    assert "no manual control, which POSCTL needs" in arm.model
    assert verdict.agree


@pytest.mark.parametrize(
    ("stem", "px4"),
    [
        ("return_and_disarm_one_cycle", "stays (OFFBOARD), disarmed"),
        ("disarm_before_return_one_cycle", "stays (AUTO_RTL), disarmed"),
    ],
)
def test_a_return_in_the_cycle_px4_disarms_is_not_judged(stem: str, px4: str) -> None:
    """Two disagreements of a live campaign on the 1.18 head (one confirmed): a stream with
    losses every 0.5 s (COM_OF_LOSS_T 0.33) whose last setpoint and a disarm reach PX4 in one
    Commander cycle. PX4's next status is already disarmed, so its return cannot be read; the
    verdict had called it "stays" against the model's return. The earlier returns are judged."""
    params = {"COM_OF_LOSS_T": 0.33, "COM_OBL_RC_ACT": 3.0, "FUZZOFF_RC_PRESENT": 1.0}
    verdict = _judge(f"{stem}-1.18.0-beta1-head", params)
    *earlier, last = [i for i in verdict.items if i.what == "automatic return"]
    assert (last.px4, last.model, last.agree) == (px4, "back to OFFBOARD", None)
    assert last.note.startswith("not judged: PX4 disarmed in the cycle the stream came back")
    assert earlier and all(i.agree and i.px4 == "back to OFFBOARD" for i in earlier)
    assert verdict.agree


def test_a_heartbeat_still_showing_the_failsafe_after_the_stream_is_back_is_not_a_mode_change() -> (
    None
):
    """The reproducer above replayed on the 1.18 head: a 1 Hz HEARTBEAT showed AUTO_RTL 11 ms
    after the model's signal came back, before PX4's next check pass ended the failsafe. The
    model took it for a mode the pilot chose (no command for it), so the three losses after it
    were "no loss predicted"; it now keeps the intention, and every loss, action and return
    agrees."""
    params = {"COM_OF_LOSS_T": 0.33, "COM_OBL_RC_ACT": 3.0, "FUZZOFF_RC_PRESENT": 1.0}
    verdict = _judge("heartbeat_in_failsafe_after_resume-1.18.0-beta1-head", params)
    assert not [i for i in verdict.items if i.what in ("offboard loss", "recorded vs model")]
    losses = [i for i in verdict.items if i.what == "failsafe action"]
    assert len(losses) == 7 and all(i.agree and i.px4 == "AUTO_RTL" for i in losses)
    assert verdict.agree


def test_a_disagreement_confirmed_before_is_counted_not_followed_up_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    config = AgainstConfig(build=bundle.Build(tmp_path, "1.15.4"), save_dir=None)
    campaign = Campaign(config, log=lambda line: None)
    stream = _stream(TEN_HZ, PLAN)
    sent: list[str] = []

    def send(scenario: Scenario, purpose: str) -> Example:
        sent.append(purpose)
        verdict = Verdict("1.15.4", "ulog", [_item(3.0, "rejected (1)", "accepted: armed")])
        example = Example(len(sent), scenario, "differ", verdict=verdict, purpose=purpose)
        campaign.result.examples.append(example)
        return example

    monkeypatch.setattr(campaign, "send", send)
    monkeypatch.setattr(campaign, "spent", lambda: True)  # no shrinking
    campaign.searched(send(stream, "search"))
    campaign.searched(send(stream, "search"))
    assert sent == ["search", "confirm", "search"]
    (case,) = campaign.result.disagreements
    assert case.confirmed is True and case.seen_again == [3]
