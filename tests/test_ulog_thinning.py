"""A ULog lint reads only the rows of PX4's own high-rate setpoint topics a check can judge
(``fuzzoff/formats/ulog/thinning.py``, issue 31): the findings and the gate model's timeline are
the same as when every row is read, on every corpus ULog and on logged flights whose declared
setpoint is one of the thinned topics, with bad content in it."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.engine import lint_file
from fuzzoff.events import (
    ActuatorMotors,
    AttitudeSetpoint,
    Command,
    CommandAck,
    ControlMode,
    Event,
    RatesSetpoint,
    ThrustSetpoint,
    TorqueSetpoint,
    VehicleStatus,
)
from fuzzoff.formats.ulog.reader import UlogSource
from fuzzoff.formats.ulog.thinning import SELECTED_BY, TABLES
from fuzzoff.formats.ulog.writer import write_ulog
from fuzzoff.profiles import VEHICLE_TYPES, Profile
from fuzzoff.releases import RELEASES
from fuzzoff.tables.control_mode import table_for
from fuzzoff.timeline import Timeline

ROOT = Path(__file__).resolve().parent.parent
ULOGS = sorted((ROOT / "corpora").rglob("*.ulg"))

SWITCH_T, LEAVE_T, END_T = 1.5, 4.0, 6.0
OFFBOARD, POSCTL = 14, 2


def _lint(path: Path, every_row: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[Any, ...]:
    """The findings (every field a user sees) and the gate timeline of one lint."""
    monkeypatch.setattr(UlogSource, "every_row", every_row)
    timelines: dict[str, Timeline] = {}
    report = lint_file(path, timelines=timelines)
    findings = [(f.code, repr(f.to_json())) for f in report.findings]
    transitions = {v: [repr(tr) for tr in tl.transitions] for v, tl in timelines.items()}
    return findings, transitions, report.complete, report.problems, report.stats["duration_s"]


def _events(path: Path, every_row: bool) -> list[Event]:
    source = UlogSource(path, every_row=every_row)
    with source:
        source.probe()
        return list(source.events())


def test_every_table_is_thinned_by_its_own_flags() -> None:
    """The thinning knows every table a profile can have (a new table must be added there)."""
    for release in RELEASES:
        for vehicle in VEHICLE_TYPES:
            table = table_for(Profile(px4=release.name, vehicle=vehicle))
            assert not table or any(table is known for known in TABLES), (release.name, vehicle)
    assert SELECTED_BY["rates"] == {"body_rate"}
    assert SELECTED_BY["thrust"] == {"thrust_and_torque", "actuator"}


@pytest.mark.parametrize("path", ULOGS, ids=lambda p: str(p.relative_to(ROOT / "corpora")))
def test_corpus_ulog_findings_are_those_of_every_row(
    path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert _lint(path, True, monkeypatch) == _lint(path, False, monkeypatch)


def _ticks(start: float, stop: float, period: float) -> list[float]:
    return [round(start + i * period, 6) for i in range(math.ceil((stop - start) / period))]


def _flight(flags: dict[str, bool], setpoint: Callable[[float], list[Event]]) -> list[Event]:
    """Offboard from 1.5 s to 4 s with ``flags`` declared, the companion's setpoints from 1 s to
    4.5 s, and PX4's controllers writing the same topics at 50 Hz all along (all logged)."""
    out: list[Event] = [
        Command(t=SWITCH_T, command=176, params=(1.0, 6.0, 0, 0, 0, 0, 0), from_external=True),
        CommandAck(t=SWITCH_T + 0.02, command=176, result=0),
    ]
    for t in _ticks(0.0, END_T, 0.1):
        out.append(ControlMode(t=t, origin="vehicle", **flags))
        nav = OFFBOARD if SWITCH_T + 0.05 <= t < LEAVE_T else POSCTL
        out.append(VehicleStatus(t=t, origin="vehicle", nav_state=nav, armed=t >= 0.5))
    for t in _ticks(0.0, END_T, 0.02):
        own = 0.005 + t  # PX4's rows, beside the companion's
        out += [
            RatesSetpoint(
                t=own, origin="vehicle", roll=0.0, pitch=0.0, yaw=0.0, thrust_body=(0.0, 0.0, -0.5)
            ),
            ThrustSetpoint(t=own, origin="vehicle", xyz=(0.0, 0.0, -0.5)),
            TorqueSetpoint(t=own, origin="vehicle", xyz=(0.0, 0.0, 0.0)),
            AttitudeSetpoint(
                t=own, origin="vehicle", q_d=(1.0, 0.0, 0.0, 0.0), thrust_body=(0.0, 0.0, -0.5)
            ),
            ActuatorMotors(t=own, origin="vehicle", control=(0.5,) * 4 + (math.nan,) * 4),
        ]
        if 1.0 <= t < LEAVE_T + 0.5:
            out += setpoint(t)
    return sorted(out, key=lambda e: e.t)


def _bad_rates(t: float) -> list[Event]:
    yaw = math.nan if 2.0 <= t < 2.5 else 0.1
    return [
        RatesSetpoint(
            t=t, origin="vehicle", roll=0.0, pitch=0.0, yaw=yaw, thrust_body=(0.0, 0.0, -0.6)
        )
    ]


def _bad_thrust_torque(t: float) -> list[Event]:
    z = -1.5 if 2.0 <= t < 2.5 else -0.6
    return [
        ThrustSetpoint(t=t, origin="vehicle", xyz=(0.0, 0.0, z)),
        TorqueSetpoint(t=t, origin="vehicle", xyz=(0.0, 0.0, 0.01)),
    ]


def _bad_attitude(t: float) -> list[Event]:
    q = (2.0, 0.0, 0.0, 0.0) if 2.0 <= t < 2.5 else (1.0, 0.0, 0.0, 0.0)
    return [AttitudeSetpoint(t=t, origin="vehicle", q_d=q, thrust_body=(0.0, 0.0, -0.6))]


def _bad_motors(t: float) -> list[Event]:
    level = math.nan if 2.0 <= t < 2.5 else 0.5
    return [ActuatorMotors(t=t, origin="vehicle", control=(level,) * 4 + (math.nan,) * 4)]


FLIGHTS: dict[str, tuple[dict[str, bool], Callable[[float], list[Event]], str]] = {
    "body_rate": ({"body_rate": True}, _bad_rates, "1.15.4"),
    "thrust_and_torque": ({"thrust_and_torque": True}, _bad_thrust_torque, "1.15.4"),
    "attitude": ({"attitude": True}, _bad_attitude, "1.15.4"),
    "direct_actuator": ({"direct_actuator": True}, _bad_motors, "1.15.4"),
}


@pytest.mark.parametrize("name", sorted(FLIGHTS))
def test_logged_setpoints_in_offboard_are_judged_as_before(
    name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    flags, setpoint, release = FLIGHTS[name]
    path = write_ulog(tmp_path / f"{name}.ulg", _flight(flags, setpoint), px4_version=release)
    thinned = _lint(path, False, monkeypatch)
    assert thinned == _lint(path, True, monkeypatch)
    codes = {code for code, _ in thinned[0]}
    assert codes & {"OFB401", "OFB402", "OFB403", "OFB405", "OFB406", "OFB407", "OFB408"}, codes


def test_px4_own_rows_outside_offboard_are_not_read(tmp_path: Path) -> None:
    """Of PX4's 50 Hz rows, the lint reads the first and those inside offboard (with a margin);
    ``every_row=True`` reads them all."""
    events = _flight({"body_rate": True}, _bad_rates)
    path = write_ulog(tmp_path / "rates.ulg", events, px4_version="1.15.4")
    logged = sum(isinstance(e, RatesSetpoint) for e in events)
    every = [e for e in _events(path, True) if isinstance(e, RatesSetpoint)]
    thinned = [e for e in _events(path, False) if isinstance(e, RatesSetpoint)]
    assert len(every) == logged
    assert thinned[0] == every[0]
    assert all(SWITCH_T < e.t <= LEAVE_T + 1.1 for e in thinned[1:])
    assert len(thinned) < len(every) * 0.75
    # Under a position declaration no rates row is the companion's: only the first is read.
    position = _flight({"position": True}, lambda t: [])
    path = write_ulog(tmp_path / "position.ulg", position, px4_version="1.15.4")
    assert sum(isinstance(e, RatesSetpoint) for e in _events(path, False)) == 1
