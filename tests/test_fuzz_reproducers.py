"""Reproducers that reproduce: ``fuzzoff replay`` checks again exactly the property that failed,
on the stream it failed on, and says "still fails" or "fixed" truthfully for every property;
a reproducer whose recording is truncated or changed is refused, not replayed."""

from __future__ import annotations

import json
import re
import socket
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.engine import lint_file
from fuzzoff.events import (
    Command,
    ControlMode,
    Event,
    SetPositionTargetLocal,
    TrajectorySetpoint,
)
from fuzzoff.findings import Finding
from fuzzoff.fuzz import properties, recordings, stream_file
from fuzzoff.fuzz.known import KNOWN
from fuzzoff.fuzz.mutate import scenario_from_recording
from fuzzoff.fuzz.properties import PROPERTIES, FuzzContext
from fuzzoff.fuzz.reproducers import save
from fuzzoff.fuzz.scenario import Scenario, run
from tests.helpers import CORPORA, run_cli

SEED_7 = CORPORA / "fuzz" / "round-trip-1.15-mc-mavros-46ae30f4.expected.json"


def _replay(path: Path) -> dict[str, Any]:
    out = run_cli(["replay", str(path), "--format", "json"])
    assert out.returncode in (0, 1), out.stderr
    data: dict[str, Any] = json.loads(out.stdout)
    assert out.returncode == (1 if data["property_still_fails"] else 0)
    return data


def test_the_seed_7_round_trip_reproducer_replays_as_fixed() -> None:
    """``fuzzoff fuzz --px4 1.15 --vehicle mc --examples 200 --seed 7`` failed the round trip:
    the MAVROS stream judged directly gave OFB202 at 1.003 s (the state still POSCTL 0.5 s
    after the model's switch), its ROS 1 bag did not (``/mavros/state`` comes over a link and
    may lag by 0.5 s). The stream is now judged as its bag is; the reproducer kept the stream,
    so the replay checks the round trip itself again, not only the bag."""
    data = _replay(SEED_7)
    assert data["rechecked_on"] == "stream"
    assert data["findings_match"]
    assert data["verdict"] == "fixed" and data["problems"] == []


def test_a_mavros_state_is_judged_in_the_stream_as_in_its_bag(tmp_path: Path) -> None:
    """The seed-7 stream: the same findings from the stream as from the bag written of it,
    and no OFB202 for a state that lags the switch by the link's 0.5 s."""
    spec = json.loads(SEED_7.read_text())
    events = stream_file.read_events(SEED_7.parent / spec["stream"])
    scenario = Scenario("1.15", "mc", "mavros", events)
    bag = recordings.write(scenario, tmp_path / "seed7.bag", "rosbag1")
    direct = [(f.code, f.time_s) for f in run(scenario)]
    assert direct == [(f.code, f.time_s) for f in lint_file(bag, scenario.settings()).findings]
    assert "OFB202" not in {code for code, _ in direct}


def _loss_stream() -> Scenario:
    """ROS 2, 10 Hz, armed and switched, a 1.5 s silence: a loss failsafe OFB103 explains."""
    events: list[Event] = []
    for i in range(40):
        t = round(i * 0.1, 4)
        if 1.5 <= t < 3.0:
            continue
        events.append(ControlMode(t=t, position=True, sender_time_us=round(t * 1e6)))
        events.append(
            TrajectorySetpoint(
                t=t + 0.001, position=(0.0, 0.0, -2.0), sender_time_us=round((t + 0.001) * 1e6)
            )
        )
    sender = dict(source_system=0, source_component=0, from_external=True, transport="ros2")
    events += [
        Command(t=1.0, command=400, params=(1.0,) + (0.0,) * 6, sender_time_us=1_000_000, **sender),
        Command(
            t=1.1, command=176, params=(1.0, 6.0) + (0.0,) * 5, sender_time_us=1_100_000, **sender
        ),
    ]
    return Scenario("1.15", "mc", "ros2", tuple(sorted(events, key=lambda e: e.t)))


def _without(codes: set[str]) -> Callable[..., list[Finding]]:
    """A fault in the rules: ``codes`` no longer fire."""
    real = properties.run

    def run(*args: Any, **kwargs: Any) -> list[Finding]:
        return [f for f in real(*args, **kwargs) if f.code not in codes]

    return run


def _lossy_mcap_writer(monkeypatch: pytest.MonkeyPatch) -> None:
    """A fault in a writer: the last message is not written."""
    from fuzzoff.formats.mcap import writer as mcap

    real = mcap.write_mcap

    def write(path: Any, events: Any, **kwargs: Any) -> Path:
        return real(path, list(events)[:-1], **kwargs)

    monkeypatch.setattr(mcap, "write_mcap", write)


def _cut_raises(monkeypatch: pytest.MonkeyPatch) -> None:
    """A fault in a reader: a cut recording raises instead of being read up to the cut."""
    real = properties.lint_file

    def lint(path: Path, *args: Any, **kwargs: Any) -> Any:
        if Path(path).name.startswith("cut"):
            raise RuntimeError("unexpected end of data")
        return real(path, *args, **kwargs)

    monkeypatch.setattr(properties, "lint_file", lint)


def _early_loss(monkeypatch: pytest.MonkeyPatch) -> None:
    """A fault in the gate model as the invariants see it: the loss comes 0.5 s early."""
    from fuzzoff.gate import params

    real = params.loss_timeout
    monkeypatch.setattr(params, "loss_timeout", lambda px4, p: real(px4, p) + 0.5)


def _runs_drop_a_finding(monkeypatch: pytest.MonkeyPatch) -> None:
    """A fault in the checks' runs: given the stream as runs, one finding is lost."""
    real = properties.run

    def run(*args: Any, batching: bool = True, **kwargs: Any) -> list[Finding]:
        found = real(*args, batching=batching, **kwargs)
        return found[:-1] if batching else found

    monkeypatch.setattr(properties, "run", run)


FAULTS: dict[str, Callable[[pytest.MonkeyPatch], None]] = {
    "explained": lambda mp: mp.setattr(properties, "run", _without({"OFB103", "OFB101"})),
    "round-trip": _lossy_mcap_writer,
    "truncation": _cut_raises,
    "invariants": _early_loss,
    "runs": _runs_drop_a_finding,
}


@pytest.mark.parametrize("prop", sorted(FAULTS))
def test_replay_says_still_fails_then_fixed_for_every_property(tmp_path: Path, prop: str) -> None:
    """Each property's reproducer, with a fault in fuzzoff that breaks that property: the
    replay checks that property again on the saved stream, as the campaign checks it (the
    same problems), and says "still fails"; once the fault is gone, "fixed"."""
    scenario = _loss_stream()
    spec_path = save(prop, scenario, ["(planted)"], tmp_path, cut_fraction=0.6)
    spec = json.loads(spec_path.read_text())
    if prop != "truncation":
        spec.pop("cut_fraction")
        spec_path.write_text(json.dumps(spec))
    assert PROPERTIES[prop].check(scenario, FuzzContext(cut_fraction=0.6)) == []

    patch = pytest.MonkeyPatch()
    FAULTS[prop](patch)
    try:
        broken = _replay(spec_path)
        expected = PROPERTIES[prop].check(scenario, FuzzContext(cut_fraction=0.6))
    finally:
        patch.undo()
    assert broken["verdict"] == "still fails" and broken["rechecked_on"] == "stream"
    assert broken["problems"] == expected and expected, prop
    assert _replay(spec_path)["verdict"] == "fixed"


def test_replay_judges_a_from_reproducer_with_the_recorded_answers(tmp_path: Path) -> None:
    """A ``--from`` counterexample is a perturbed copy of a recording: its vehicle side answered
    the unperturbed stream, and the campaign left out the hazards it contradicts. The
    reproducer says so, and the replay judges it the same way."""
    recording = CORPORA / "mcap" / "from_switch_rejected_perturbed.mcap"
    scenario = scenario_from_recording(recording, "1.15", "mc", {})
    as_campaign = save("explained", scenario, ["x"], tmp_path / "a", recorded_answers=True)
    assert _replay(as_campaign)["verdict"] == "fixed"
    generated = save("explained", scenario, ["x"], tmp_path / "b", recorded_answers=False)
    assert "controller at 2.482 s" in _replay(generated)["problems"][0]


def _saved(tmp_path: Path) -> tuple[Path, Path]:
    spec_path = save("invariants", _loss_stream(), ["x"], tmp_path)
    return spec_path, tmp_path / json.loads(spec_path.read_text())["recording"]


def _one_error_line(stderr: str) -> str:
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    return lines[0]


def test_a_truncated_recording_is_refused_not_replayed(tmp_path: Path) -> None:
    spec_path, recording = _saved(tmp_path)
    data = recording.read_bytes()
    recording.write_bytes(data[: len(data) // 2])
    out = run_cli(["replay", str(spec_path)])
    assert out.returncode == 2 and out.stdout == ""
    line = _one_error_line(out.stderr)
    assert f"{recording}: the recording is truncated: {len(data) // 2:,} of the" in line


def test_a_recording_changed_since_it_was_saved_is_refused(tmp_path: Path) -> None:
    spec_path, recording = _saved(tmp_path)
    data = bytearray(recording.read_bytes())
    data[-3] ^= 0xFF
    recording.write_bytes(bytes(data))
    out = run_cli(["replay", str(spec_path)])
    assert out.returncode == 2
    assert "the recording changed since it was saved" in _one_error_line(out.stderr)


def test_an_older_reproducer_with_a_cut_recording_is_refused_as_incomplete(
    tmp_path: Path,
) -> None:
    """Reproducers saved before the size and digest were kept: the recording read completely
    when it was saved, so a part that no longer reads means it was cut."""
    spec = json.loads(
        (CORPORA / "fuzz" / "explained-1.16-mc-mavlink-480969c1.expected.json").read_text()
    )
    data = (CORPORA / "fuzz" / spec["recording"]).read_bytes()
    (tmp_path / spec["recording"]).write_bytes(data[:-7])
    spec_path = tmp_path / "explained-1.16-mc-mavlink-480969c1.expected.json"
    spec_path.write_text(json.dumps(spec))
    out = run_cli(["replay", str(spec_path)])
    assert out.returncode == 2
    assert "the recording is incomplete" in _one_error_line(out.stderr)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda s: s.replace('"t": 0.1,', '"t": "soon",', 1), "events[2].t"),
        (lambda s: s.replace('"position": true', '"position": 3', 1), "events[0].position"),
        (lambda s: s.replace('"kind": "control_mode"', '"kind": "teleport"', 1), "events[0].kind"),
        (lambda s: s.replace('"origin": "sent"', '"origin": "elsewhere"', 1), "events[0].origin"),
        (lambda s: s[: len(s) // 2], "not a readable stream file"),
    ],
)
def test_a_damaged_stream_file_is_one_line_naming_the_event_and_field(
    tmp_path: Path, change: Callable[[str], str], field: str
) -> None:
    spec_path, _ = _saved(tmp_path)
    stream = tmp_path / json.loads(spec_path.read_text())["stream"]
    stream.write_text(change(stream.read_text()))
    out = run_cli(["replay", str(spec_path)])
    assert out.returncode == 2
    line = _one_error_line(out.stderr)
    assert line.startswith(f"error: {spec_path}: stream ({stream.name}): ") and field in line


CORPUS = sorted((CORPORA / "fuzz").glob("*.expected.json"))


@pytest.mark.parametrize("spec_path", CORPUS, ids=[p.name for p in CORPUS])
def test_every_corpus_reproducer_replays_with_its_verdict(spec_path: Path) -> None:
    """A reproducer kept as a regression case (``"fixed"``) replays as fixed; any other shows
    one of fuzzoff's known problems and still fails, so a fix is noticed (then mark it fixed
    and drop its entry from ``fuzzoff/fuzz/known.py``)."""
    spec = json.loads(spec_path.read_text())
    data = _replay(spec_path)
    if "fixed" in spec:
        assert data["verdict"] == "fixed", data["problems"]
    else:
        assert data["verdict"] == "still fails"
        assert any(re.search(k, p) for k in KNOWN for p in data["problems"]), data["problems"]


def test_every_known_problem_has_a_reproducer_that_still_fails() -> None:
    shown = [
        p
        for path in CORPUS
        if "fixed" not in (spec := json.loads(path.read_text()))
        for p in spec["problems"]
    ]
    for pattern, what in KNOWN.items():
        assert any(re.search(pattern, p) for p in shown), f"no reproducer shows: {what}"


def test_a_truncated_mavlink_reproducer_is_not_sent_to_a_live_px4(tmp_path: Path) -> None:
    """``--to``: the recording is checked before anything is sent (it was sent, exit 0)."""
    scenario = Scenario(
        "1.15",
        "mc",
        "mavlink",
        tuple(
            SetPositionTargetLocal(
                t=round(0.1 * i, 4),
                vehicle="1",
                type_mask=3576,
                target_system=1,
                target_component=1,
                source_system=245,
                source_component=191,
            )
            for i in range(10)
        ),
    )
    spec_path = save("explained", scenario, ["x"], tmp_path)
    recording = tmp_path / json.loads(spec_path.read_text())["recording"]
    recording.write_bytes(recording.read_bytes()[:-40])
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sink:
        sink.bind(("127.0.0.1", 0))
        sink.settimeout(0.5)
        out = run_cli(["replay", str(spec_path), "--to", f"udp:127.0.0.1:{sink.getsockname()[1]}"])
        assert out.returncode == 2
        assert "the recording is truncated" in _one_error_line(out.stderr)
        with pytest.raises(TimeoutError):
            sink.recv(4096)
