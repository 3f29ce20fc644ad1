"""One fuzz example: a profile, the gate parameters, a transport and the events of the stream.

A ``Scenario`` is what the strategies draw and what a reproducer stores. ``run`` lints it with
the engine exactly as ``fuzzoff lint`` would lint the recording the scenario is written to
(the profile and the parameters as command-line settings, see ``lint_args``; the vehicle's
status as it reaches that recording, see ``as_recorded``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import field, replace
from typing import Any, Literal

from fuzzoff.config import Settings
from fuzzoff.engine import run_events
from fuzzoff.events import Event, VehicleStatus, Where, event_from_dict, event_to_dict
from fuzzoff.findings import Finding
from fuzzoff.formats.registry import written_for
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import Profile, px4_profile_for
from fuzzoff.recording import RecordingInfo
from fuzzoff.releases import PX4Profile
from fuzzoff.timeline import Timeline

TransportName = Literal["ros2", "mavlink", "mavros"]
TRANSPORTS: tuple[TransportName, ...] = ("ros2", "mavlink", "mavros")

AUTOPILOT = (1, 1)
"""The vehicle every command and MAVLink setpoint addresses (PX4's default ``MAV_SYS_ID`` and
``MAV_COMP_ID_AUTOPILOT1``): PX4 refuses a COMMAND_LONG to system 0 with FAILED before its
offboard gate sees it, so a reproducer that broadcast its commands never reached the gate."""
COMPANION = (245, 191)
"""The companion's own MAVLink (sysid, compid): not 1, the autopilot's, which PX4 takes for
itself; 191 is ``MAV_COMP_ID_ONBOARD_COMPUTER``."""

RECORDING_FORMAT: dict[str, str] = {t: written_for(t)[0].name for t in TRANSPORTS}
"""The format a reproducer of each transport is saved in (task: MCAP for ROS 2, tlog for
MAVLink; a MAVROS stream is a ROS 1 bag, since a tlog cannot say it came through MAVROS)."""


@dataclass(frozen=True, slots=True)
class Scenario:
    px4: PX4Profile
    vehicle: str
    transport: TransportName
    events: tuple[Event, ...]
    params: Mapping[str, float] = field(default_factory=dict)

    @property
    def profile(self) -> Profile:
        return Profile(px4=self.px4, vehicle=self.vehicle, px4_detected=True, vehicle_detected=True)

    @property
    def duration(self) -> float:
        return self.events[-1].t if self.events else 0.0

    def settings(self, base: Settings | None = None) -> Settings:
        """``base`` (the campaign's rule selection) with this scenario's profile and params.
        Not looked up again per recording (``Settings.discovery``): the recordings of a
        scenario are fuzzoff's own temporary files, and a configuration found above them
        would replace the scenario's profile with the one detected from the file."""
        base = base or Settings()
        return replace(
            base, px4=self.px4, vehicle=self.vehicle, params=dict(self.params), discovery=None
        )

    def lint_args(self) -> list[str]:
        """The ``fuzzoff lint`` arguments that judge a recording of this scenario the same way."""
        args = ["--px4", self.px4, "--vehicle", self.vehicle]
        for name, value in sorted(self.params.items()):
            args += ["--param", f"{name}={value:g}"]
        return args

    def describe(self) -> str:
        params = ", ".join(f"{k}={v:g}" for k, v in sorted(self.params.items()))
        return (
            f"PX4 {self.px4}, {self.vehicle}, {self.transport}, {len(self.events)} events over "
            f"{self.duration:.2f} s" + (f", {params}" if params else "")
        )

    def to_json(self) -> dict[str, Any]:
        return {
            "px4": self.px4,
            "vehicle": self.vehicle,
            "transport": self.transport,
            "params": dict(self.params),
            "events": [_jsonable(event_to_dict(e)) for e in self.events],
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Scenario:
        events = tuple(event_from_dict(dict(e)) for e in data["events"])
        return cls(
            px4=px4_profile_for(str(data["px4"])),
            vehicle=str(data["vehicle"]),
            transport=data["transport"],
            events=events,
            params={str(k): float(v) for k, v in dict(data.get("params", {})).items()},
        )


def _jsonable(value: Any) -> Any:
    """NaN as the string ``"nan"`` (what ``event_from_dict`` reads back), for strict JSON."""
    if isinstance(value, float) and value != value:
        return "nan"
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_jsonable(v) for v in value]
    return value


LINK_STATUS: dict[str, Where] = {"mavlink": Where("HEARTBEAT"), "mavros": Where("/mavros/state")}
"""Where the vehicle's status of these transports reaches a recording: a tlog holds the
autopilot's HEARTBEAT, a MAVROS bag ``/mavros/state``, both over a link, and the gate
comparison lets a status that came over a link lag the vehicle (``gate.compare.LINK_LAG``).
The readers give the status that topic; the generated status has none."""


def as_recorded(events: Sequence[Event], transport: str) -> list[Event]:
    """``events`` with each vehicle status that carries no topic given the one its recording
    gives it (``LINK_STATUS``), so that the stream is judged as ``fuzzoff lint`` judges the
    recording: without it a MAVROS state 0.5 s behind a switch was a disagreement (OFB202) in
    the stream and the link's lag in its bag (the round trip failed on seed 7)."""
    where = LINK_STATUS.get(transport)
    if where is None:
        return list(events)
    return [
        replace(e, where=where) if isinstance(e, VehicleStatus) and not e.where.topic else e
        for e in events
    ]


def info_for(events: Sequence[Event], fmt: str) -> RecordingInfo:
    """What a reader of ``fmt`` would say about a recording holding ``events``."""
    return RecordingInfo("fuzz", fmt, kinds={e.kind for e in events})


def run(
    scenario: Scenario,
    base: Settings | None = None,
    *,
    events: Sequence[Event] | None = None,
    timelines: dict[str, Timeline] | None = None,
    batching: bool = True,
) -> list[Finding]:
    """The findings ``fuzzoff lint`` gives for the recording of the scenario (or of ``events``
    instead of its own, judged with its profile), sorted like the lint report."""
    stream = as_recorded(scenario.events if events is None else events, scenario.transport)
    info = info_for(stream, RECORDING_FORMAT[scenario.transport])
    settings = scenario.settings(base)
    findings, _ = run_events(
        stream, info, scenario.profile, settings, timelines=timelines, batching=batching
    )
    findings = [f for f in findings if settings.enabled(f.code)]
    findings.sort(key=lambda f: (-1e300 if f.time_s is None else f.time_s, f.vehicle, f.code))
    return findings
