"""Save a shrunk counterexample as a recording + ``NAME.expected.json``, and load it back.

The recording is written by the real writers in the transport's format (MCAP for ROS 2, tlog
for MAVLink, ROS 1 bag for MAVROS). ``NAME.expected.json`` has the corpus keys of
``tests/test_corpora.py`` (``recording``, ``args``, ``exit_status``, ``complete``,
``findings``: what ``fuzzoff lint`` says about the recording when it is saved) and:

* ``property``: the property the example broke; ``problems``: what it said;
* ``scenario``: ``px4``, ``vehicle``, ``transport``, ``params`` (to rebuild it for replay);
* ``stream``: the file holding the stream the property failed on (``fuzz.stream_file``);
* ``recorded_answers``: the stream's vehicle side is a recording's (``--from``), as the
  campaign judged it;
* ``recording_bytes``, ``recording_sha256``: the recording as saved (a truncated or changed
  one is refused, not replayed);
* ``setup``: what a sender sets on a live PX4 before it sends the stream (``Setup``): the PX4
  parameters, whether a manual control is present, the starting state and the MAVLink ids;
* ``cut_fraction``: for ``truncation``, where the recording was cut.

``make test`` replays the findings (a regression test of the rules on the reproducer);
``fuzzoff replay`` also checks the property again on the saved stream, exactly as the campaign
did (is the bug still there?). Reproducers saved before streams were kept are checked on the
recording's events instead, and say so.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import field, replace
from pathlib import Path
from typing import Any

from fuzzoff.catalog import expand_selectors
from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.findings import FileReport, Severity
from fuzzoff.fuzz import recordings, stream_file
from fuzzoff.fuzz.properties import PROPERTIES, FuzzContext
from fuzzoff.fuzz.scenario import AUTOPILOT, COMPANION, RECORDING_FORMAT, TRANSPORTS, Scenario
from fuzzoff.gate.params import RC_PRESENT
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import (
    DEFAULT_PX4,
    DEFAULT_VEHICLE,
    ProfileError,
    px4_profile_for,
    vehicle_type_for,
)

DEFAULT_DIR = Path(".fuzzoff/reproducers")
"""Where ``fuzzoff fuzz`` saves reproducers unless ``--save-dir`` says: a tool folder of the
working folder (as ``.pytest_cache``), made only when a counterexample is saved."""


@dataclass(frozen=True, slots=True)
class Setup:
    """What a sender sets up on a live PX4 before it sends the stream, so that PX4 judges it
    as the gate model did: the PX4 parameters (PARAM_SET, read back), a manual control (RC or
    joystick) present or not, the state the stream starts from, and who addresses whom."""

    params: dict[str, float]
    """PX4 parameters by name (``COM_OF_LOSS_T``...; fuzzoff's own assumptions left out)."""
    manual_control: bool
    """The model assumed an RC or joystick present (``FUZZOFF_RC_PRESENT``, default 1)."""
    start_armed: bool = False
    """The model starts disarmed, in a mode other than OFFBOARD."""
    autopilot: tuple[int, int] = AUTOPILOT
    """The (sysid, compid) the stream's commands and setpoints address."""
    companion: tuple[int, int] | None = None
    """The (sysid, compid) the recording's MAVLink stream is sent from (None: not MAVLink)."""

    def to_json(self) -> dict[str, Any]:
        return {
            "params": dict(sorted(self.params.items())),
            "manual_control": self.manual_control,
            "start": {"armed": self.start_armed, "in_offboard": False},
            "autopilot": {"system": self.autopilot[0], "component": self.autopilot[1]},
            "companion": None
            if self.companion is None
            else {"system": self.companion[0], "component": self.companion[1]},
        }

    def describe(self) -> str:
        params = ", ".join(f"{k}={v:g}" for k, v in sorted(self.params.items()))
        return "; ".join(
            [
                f"PX4 parameters {params}" if params else "PX4 parameters at their defaults",
                "manual control " + ("present" if self.manual_control else "absent"),
                "start " + ("armed" if self.start_armed else "disarmed") + ", not in OFFBOARD",
            ]
        )


def setup_for(scenario: Scenario) -> Setup:
    """The setup the gate model judged ``scenario`` with."""
    params = {k: float(v) for k, v in scenario.params.items() if k != RC_PRESENT}
    mavlink = scenario.transport == "mavlink"
    return Setup(
        params=params,
        manual_control=bool(scenario.params.get(RC_PRESENT, 1.0)),
        companion=COMPANION if mavlink else None,
    )


def name_for(prop: str, scenario: Scenario) -> str:
    digest = hashlib.sha256(json.dumps(scenario.to_json(), sort_keys=True).encode()).hexdigest()
    return f"{prop}-{scenario.px4}-{scenario.vehicle}-{scenario.transport}-{digest[:8]}"


def expected_findings(report: FileReport) -> list[dict[str, Any]]:
    out = []
    for f in report.findings:
        entry: dict[str, Any] = {
            "code": f.code,
            "severity": f.severity.label,
            "time_s": None if f.time_s is None else round(f.time_s, 6),
        }
        if f.vehicle:
            entry["vehicle"] = f.vehicle
        out.append(entry)
    return out


def _rules_json(settings: Settings) -> dict[str, Any]:
    """The campaign's rule settings beyond ``ignore`` (from its configuration file): the
    property is checked again with them. Left out where they are the defaults."""
    out: dict[str, Any] = {}
    if settings.select:
        out["select"] = sorted(settings.select)
    if settings.severity:
        out["severity"] = {code: sev.label for code, sev in sorted(settings.severity.items())}
    if settings.options:
        out["options"] = {code: dict(o) for code, o in sorted(settings.options.items())}
    return out


def exit_status(report: FileReport, settings: Settings) -> int:
    if not report.complete:
        return 2
    return 1 if any(f.severity >= settings.fail_on for f in report.findings) else 0


def save(
    prop: str,
    scenario: Scenario,
    problems: list[str],
    directory: Path,
    *,
    cut_fraction: float | None = None,
    base: Settings | None = None,
    recorded_answers: bool = False,
) -> Path:
    """Write the reproducer; returns the path of its ``expected.json``. ``base``: the
    campaign's rule selection (``--ignore``), kept in the reproducer's arguments;
    ``recorded_answers``: the campaign perturbed a recording (``--from``)."""
    directory.mkdir(parents=True, exist_ok=True)
    name = name_for(prop, scenario)
    fmt = RECORDING_FORMAT[scenario.transport]
    recording = directory / f"{name}{recordings.SUFFIX[fmt]}"
    recordings.write(scenario, recording, fmt)
    stream = stream_file.write(scenario, directory / f"{name}{stream_file.SUFFIX}")
    data = recording.read_bytes()
    settings = scenario.settings(base)
    report = lint_file(recording, settings)
    args = scenario.lint_args()
    if settings.ignore:
        args += ["--ignore", ",".join(sorted(settings.ignore))]
    spec: dict[str, Any] = {
        "recording": recording.name,
        "recording_bytes": len(data),
        "recording_sha256": hashlib.sha256(data).hexdigest(),
        "args": args,
        "exit_status": exit_status(report, settings),
        "complete": report.complete,
        "property": prop,
        "problems": problems,
        "scenario": {k: v for k, v in scenario.to_json().items() if k != "events"}
        | {"ignore": sorted(settings.ignore)}
        | _rules_json(settings),
        "stream": stream.name,
        "recorded_answers": recorded_answers,
        "setup": setup_for(scenario).to_json(),
        "findings": expected_findings(report),
    }
    if cut_fraction is not None:
        spec["cut_fraction"] = cut_fraction
    path = directory / f"{name}.expected.json"
    path.write_text(json.dumps(spec, indent=2) + "\n")
    return path


class ReproducerError(ValueError):
    """The file is not a reproducer (one line naming the file and what is wrong)."""


@dataclass(frozen=True, slots=True)
class Reproducer:
    """A reproducer as ``load`` checked it: every field replay uses has its type and value."""

    path: Path
    """The ``expected.json``."""
    recording: Path
    findings: list[dict[str, Any]]
    prop: str | None
    """The property it broke (None: only its findings are checked)."""
    scenario: Scenario | None
    """Profile, transport and parameters, without events (None when the file has none)."""
    ignore: frozenset[str]
    cut_fraction: float | None
    rules: Settings = field(default_factory=Settings)
    """The campaign's rule settings: ``ignore``, and ``select``, ``severity`` and ``options``
    where its configuration set them."""
    stream: Scenario | None = None
    """The scenario with the events the property failed on (None: saved without them)."""
    recorded_answers: bool = False
    size: int | None = None
    sha256: str | None = None
    """The recording as saved (None: saved before reproducers kept them)."""
    complete: bool = True
    """What ``fuzzoff lint`` said of the recording when it was saved."""
    fixed: str | None = None
    """The note of a reproducer kept as a regression case after its problem was fixed."""
    setup: Setup | None = None
    """What a sender sets up on a live PX4 first (None: the reproducer has no scenario)."""


def load(path: Path) -> Reproducer:
    """The reproducer given by its ``expected.json`` or its recording, checked field by field
    (``ReproducerError`` naming the file and the first bad field)."""
    if not path.name.endswith(".expected.json"):
        stem = path.name[: -len(path.suffix)] if path.suffix else path.name
        path = path.parent / f"{stem}.expected.json"
        if not path.exists():
            raise ReproducerError(f"{path}: no such file beside the recording")
    try:
        spec = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ReproducerError(f"{path}: not a readable reproducer: {exc}") from None
    if not isinstance(spec, dict) or "recording" not in spec:
        raise ReproducerError(f"{path}: no 'recording' key")
    try:
        return _checked(path, spec)
    except _Bad as bad:
        raise ReproducerError(f"{path}: {bad.field}: {bad.problem}") from None


class _Bad(Exception):
    def __init__(self, field: str, problem: str) -> None:
        super().__init__(field, problem)
        self.field = field
        self.problem = problem


def _checked(path: Path, spec: dict[str, Any]) -> Reproducer:
    recording = spec["recording"]
    if not isinstance(recording, str) or not recording or Path(recording).name != recording:
        # beside the JSON file, as saved: a path could make replay read or send any file
        raise _Bad("recording", f"{recording!r} is not a file name beside the reproducer")
    prop = spec.get("property")
    if prop is not None and prop not in PROPERTIES:
        raise _Bad("property", f"unknown property {prop!r}: one of {', '.join(PROPERTIES)}")
    info = spec.get("scenario")
    if info is not None and not isinstance(info, dict):
        raise _Bad("scenario", "expected an object (px4, vehicle, transport, params, ignore)")
    if prop is not None and not info:
        raise _Bad("scenario", f"missing: property {prop} cannot be checked again without it")
    cut = spec.get("cut_fraction")
    if cut is not None and not (_is_number(cut) and 0.0 <= cut <= 1.0):
        raise _Bad("cut_fraction", f"{cut!r} is not a number from 0 to 1")
    scenario = None if not info else _scenario(info)
    size, sha256 = spec.get("recording_bytes"), spec.get("recording_sha256")
    if size is not None and not (
        isinstance(size, int) and not isinstance(size, bool) and size >= 0
    ):
        raise _Bad("recording_bytes", f"{size!r} is not a size in bytes")
    if sha256 is not None and not (
        isinstance(sha256, str) and len(sha256) == 64 and all(c in HEX for c in sha256)
    ):
        raise _Bad("recording_sha256", f"{sha256!r} is not a SHA-256 in hexadecimal")
    recorded_answers = spec.get("recorded_answers", False)
    if not isinstance(recorded_answers, bool):
        raise _Bad("recorded_answers", f"{recorded_answers!r} is not true or false")
    complete = spec.get("complete", True)
    if not isinstance(complete, bool):
        raise _Bad("complete", f"{complete!r} is not true or false")
    fixed = spec.get("fixed")
    return Reproducer(
        path=path,
        recording=path.parent / recording,
        findings=_findings(spec.get("findings", [])),
        prop=prop,
        scenario=scenario,
        ignore=_ignore(info.get("ignore", []) if info else []),
        cut_fraction=None if cut is None else float(cut),
        rules=_rules(info or {}),
        stream=_stream(path, spec.get("stream"), scenario),
        recorded_answers=recorded_answers,
        size=size,
        sha256=sha256,
        complete=complete,
        fixed=None if fixed is None else _text(fixed, "fixed"),
        setup=None if scenario is None else _setup(spec.get("setup"), scenario),
    )


def _setup(value: Any, scenario: Scenario) -> Setup:
    """The reproducer's ``setup``; one saved before it was kept is what its scenario implies."""
    if value is None:
        return setup_for(scenario)
    if not isinstance(value, dict):
        raise _Bad("setup", "expected an object (params, manual_control, start, autopilot)")
    params = value.get("params", {})
    if not isinstance(params, dict):
        raise _Bad("setup.params", "expected an object of NAME: number")
    for name, number in params.items():
        if not _is_number(number):
            raise _Bad(f"setup.params.{name}", f"{number!r} is not a finite number")
    manual = value.get("manual_control", True)
    start = value.get("start", {})
    armed = start.get("armed", False) if isinstance(start, dict) else None
    if not isinstance(manual, bool):
        raise _Bad("setup.manual_control", f"{manual!r} is not true or false")
    if not isinstance(armed, bool):
        raise _Bad("setup.start", f"{start!r} is not an object with 'armed' true or false")
    return Setup(
        params={str(k): float(v) for k, v in params.items()},
        manual_control=manual,
        start_armed=armed,
        autopilot=_ids(value.get("autopilot"), "setup.autopilot") or AUTOPILOT,
        companion=_ids(value.get("companion"), "setup.companion"),
    )


def _ids(value: Any, field: str) -> tuple[int, int] | None:
    if value is None:
        return None
    ok = isinstance(value, dict) and all(
        isinstance(value.get(k), int) and not isinstance(value.get(k), bool) and 0 <= value[k] < 256
        for k in ("system", "component")
    )
    if not ok:
        raise _Bad(field, f"{value!r} is not an object with 'system' and 'component' from 0 to 255")
    return (value["system"], value["component"])


HEX = frozenset("0123456789abcdef")


def _stream(path: Path, name: Any, scenario: Scenario | None) -> Scenario | None:
    """The saved stream, with the reproducer's profile and parameters (``scenario``)."""
    if name is None:
        return None
    if not isinstance(name, str) or not name or Path(name).name != name:
        raise _Bad("stream", f"{name!r} is not a file name beside the reproducer")
    if scenario is None:
        raise _Bad("scenario", "missing: the stream cannot be judged without its profile")
    file = path.parent / name
    if not file.is_file():
        raise _Bad("stream", f"{name}: no such file beside the reproducer")
    try:
        events = stream_file.read_events(file)
    except stream_file.StreamFileError as exc:
        raise _Bad(f"stream ({name})", str(exc)) from None
    return replace(scenario, events=events)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _text(value: Any, field: str) -> str:
    if not isinstance(value, str):
        raise _Bad(field, f"{value!r} is not text")
    return value


def _findings(value: Any) -> list[dict[str, Any]]:
    if not isinstance(value, list):
        raise _Bad("findings", "expected a list of findings")
    for i, finding in enumerate(value):
        field = f"findings[{i}]"
        if not isinstance(finding, dict):
            raise _Bad(field, "expected an object (code, severity, time_s)")
        for key in ("code", "severity"):
            if key not in finding:
                raise _Bad(field, f"no {key!r}")
        _text(finding["code"], f"{field}.code")
        try:
            Severity.parse(_text(finding["severity"], f"{field}.severity"))
        except ValueError as exc:
            raise _Bad(f"{field}.severity", str(exc)) from None
        time_s = finding.get("time_s")
        if time_s is not None and not _is_number(time_s):
            raise _Bad(f"{field}.time_s", f"{time_s!r} is not a number or null")
        if "vehicle" in finding:
            _text(finding["vehicle"], f"{field}.vehicle")
    return value


def _scenario(info: dict[str, Any]) -> Scenario:
    """The scenario's profile as ``--px4``/``--vehicle`` would take it (``1.15.4`` is 1.15)."""
    try:
        px4 = px4_profile_for(_text(info.get("px4", DEFAULT_PX4), "scenario.px4"))
    except ProfileError as exc:
        raise _Bad("scenario.px4", str(exc)) from None
    try:
        vehicle = vehicle_type_for(_text(info.get("vehicle", DEFAULT_VEHICLE), "scenario.vehicle"))
    except ProfileError as exc:
        raise _Bad("scenario.vehicle", str(exc)) from None
    transport = info.get("transport", "ros2")
    if transport not in TRANSPORTS:
        raise _Bad("scenario.transport", f"{transport!r} is not one of {', '.join(TRANSPORTS)}")
    params = info.get("params", {})
    if not isinstance(params, dict):
        raise _Bad("scenario.params", "expected an object of NAME: number")
    for name, value in params.items():
        if not _is_number(value):
            raise _Bad(f"scenario.params.{name}", f"{value!r} is not a finite number")
    numbers = {str(k): float(v) for k, v in params.items()}
    return Scenario(px4=px4, vehicle=vehicle, transport=transport, events=(), params=numbers)


def _rules(info: dict[str, Any]) -> Settings:
    select = info.get("select", [])
    if not isinstance(select, list) or not all(isinstance(c, str) for c in select):
        raise _Bad("scenario.select", f"{select!r} is not a list of rule codes")
    severity = info.get("severity", {})
    if not isinstance(severity, dict):
        raise _Bad("scenario.severity", "expected an object of CODE: error, warning or info")
    options = info.get("options", {})
    if not isinstance(options, dict) or not all(isinstance(o, dict) for o in options.values()):
        raise _Bad("scenario.options", "expected an object of CODE: {option: value}")
    try:
        chosen = frozenset(expand_selectors(select))
        levels = {
            code: Severity.parse(_text(v, f"scenario.severity.{code}"))
            for code, v in severity.items()
        }
        expand_selectors(list(levels) + list(options))
    except ValueError as exc:
        raise _Bad("scenario.severity/options/select", str(exc)) from None
    return Settings(
        select=chosen,
        ignore=_ignore(info.get("ignore", [])),
        severity=levels,
        options={str(code): dict(o) for code, o in options.items()},
    )


def _ignore(value: Any) -> frozenset[str]:
    if not isinstance(value, list) or not all(isinstance(c, str) for c in value):
        raise _Bad("scenario.ignore", f"{value!r} is not a list of rule codes")
    try:
        return frozenset(expand_selectors(value))
    except ValueError as exc:
        raise _Bad("scenario.ignore", str(exc)) from None


def recording_problem(reproducer: Reproducer) -> str | None:
    """Why the reproducer's recording cannot be used as it was saved (missing, truncated,
    changed since), or None. A reproducer saved without its size and digest is read instead:
    one that read completely when saved must still (``SourceError`` when it cannot be read
    at all)."""
    path = reproducer.recording
    if not path.is_file():
        return f"{path}: the reproducer's recording is missing"
    if reproducer.size is not None or reproducer.sha256 is not None:
        data = path.read_bytes()
        if reproducer.size is not None and len(data) < reproducer.size:
            return (
                f"{path}: the recording is truncated: {len(data):,} of the {reproducer.size:,} "
                "bytes it was saved with"
            )
        if (reproducer.size is not None and len(data) != reproducer.size) or (
            reproducer.sha256 is not None and hashlib.sha256(data).hexdigest() != reproducer.sha256
        ):
            return f"{path}: the recording changed since it was saved (recording_sha256 differs)"
        return None
    if reproducer.complete:
        _, _, problems = recordings.read_with_info(path)
        if problems:
            return f"the recording is incomplete: {problems[0]}"
    return None


@dataclass(frozen=True, slots=True)
class Recheck:
    """The property checked again: its problems ([] = it holds now) and on what."""

    problems: list[str]
    on_stream: bool
    """True: on the saved stream, as the campaign checked it; False: on the recording's events
    (a reproducer saved without its stream)."""


def recheck(reproducer: Reproducer) -> Recheck:
    """Check the reproducer's property again, exactly as the campaign did where the stream was
    saved: the same events, rules, vehicle side (``recorded_answers``) and cut."""
    from fuzzoff.fuzz.mutate import scenario_from_recording

    if reproducer.prop is None or reproducer.scenario is None:
        return Recheck([], reproducer.stream is not None)
    scenario = reproducer.stream
    recorded_answers = reproducer.recorded_answers
    if scenario is None:
        info = reproducer.scenario
        scenario = scenario_from_recording(
            reproducer.recording, info.px4, info.vehicle, dict(info.params)
        )
        recorded_answers = True  # a reader's events: the recorded vehicle side
    ctx = FuzzContext(settings=reproducer.rules, recorded_answers=recorded_answers)
    try:
        if reproducer.cut_fraction is not None:
            ctx.cut_fraction = reproducer.cut_fraction
        return Recheck(
            PROPERTIES[reproducer.prop].check(scenario, ctx), reproducer.stream is not None
        )
    finally:
        ctx.close()
