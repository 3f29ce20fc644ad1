"""Save a shrunk counterexample as a recording + ``NAME.expected.json``, and load it back.

The recording is written by the real writers in the transport's format (MCAP for ROS 2, tlog
for MAVLink, ROS 1 bag for MAVROS). ``NAME.expected.json`` has the corpus keys of
``tests/test_corpora.py`` (``recording``, ``args``, ``exit_status``, ``complete``,
``findings``: what ``fuzzoff lint`` says about the recording when it is saved) and:

* ``property``: the property the example broke; ``problems``: what it said;
* ``scenario``: ``px4``, ``vehicle``, ``transport``, ``params`` (to rebuild it for replay);
* ``cut_fraction``: for ``truncation``, where the recording was cut.

``make test`` replays the findings (a regression test of the rules on the reproducer);
``fuzzoff replay`` also re-checks the property (is the bug still there?).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.findings import FileReport
from fuzzoff.fuzz import recordings
from fuzzoff.fuzz.properties import PROPERTIES, FuzzContext
from fuzzoff.fuzz.scenario import RECORDING_FORMAT, Scenario

DEFAULT_DIR = Path("corpora/fuzz")


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
) -> Path:
    """Write the reproducer; returns the path of its ``expected.json``. ``base``: the
    campaign's rule selection (``--ignore``), kept in the reproducer's arguments."""
    directory.mkdir(parents=True, exist_ok=True)
    name = name_for(prop, scenario)
    fmt = RECORDING_FORMAT[scenario.transport]
    recording = directory / f"{name}{recordings.SUFFIX[fmt]}"
    recordings.write(scenario, recording, fmt)
    settings = scenario.settings(base)
    report = lint_file(recording, settings)
    args = scenario.lint_args()
    if settings.ignore:
        args += ["--ignore", ",".join(sorted(settings.ignore))]
    spec: dict[str, Any] = {
        "recording": recording.name,
        "args": args,
        "exit_status": exit_status(report, settings),
        "complete": report.complete,
        "property": prop,
        "problems": problems,
        "scenario": {k: v for k, v in scenario.to_json().items() if k != "events"}
        | {"ignore": sorted(settings.ignore)},
        "findings": expected_findings(report),
    }
    if cut_fraction is not None:
        spec["cut_fraction"] = cut_fraction
    path = directory / f"{name}.expected.json"
    path.write_text(json.dumps(spec, indent=2) + "\n")
    return path


class ReproducerError(ValueError):
    """The file is not a reproducer (one line naming the file and what is wrong)."""


def load(path: Path) -> tuple[dict[str, Any], Path]:
    """(the expected.json contents, the recording's path) for a reproducer given by either."""
    if not path.name.endswith(".expected.json"):
        stem = path.name[: -len(path.suffix)] if path.suffix else path.name
        path = path.parent / f"{stem}.expected.json"
        if not path.exists():
            raise ReproducerError(f"{path}: no such file beside the recording")
    try:
        spec = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise ReproducerError(f"{path}: not a readable reproducer: {exc}") from None
    if not isinstance(spec, dict) or "recording" not in spec:
        raise ReproducerError(f"{path}: no 'recording' key")
    return spec, path.parent / str(spec["recording"])


def recheck(spec: dict[str, Any], recording: Path) -> list[str]:
    """Run the reproducer's property again on the recording's events: [] = it holds now."""
    from fuzzoff.fuzz.mutate import scenario_from_recording

    prop = spec.get("property")
    info = spec.get("scenario") or {}
    if prop not in PROPERTIES or not info:
        return []
    scenario = scenario_from_recording(
        recording,
        str(info["px4"]),
        str(info["vehicle"]),
        {str(k): float(v) for k, v in dict(info.get("params", {})).items()},
    )
    ignore = frozenset(info.get("ignore", []))
    ctx = FuzzContext(settings=Settings(ignore=ignore), recorded_answers=True)
    try:
        if "cut_fraction" in spec:
            ctx.cut_fraction = float(spec["cut_fraction"])
        return PROPERTIES[str(prop)].check(scenario, ctx)
    finally:
        ctx.close()
