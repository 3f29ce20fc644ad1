"""The gate model's timeline of a recording as rows, for ``fuzzoff gate`` and the SITL
verdict: each row a model transition (time, what, message, its docs/gate.md section, unverified
or not) or a recorded mode change, in time order."""

from __future__ import annotations

import dataclasses
from typing import Any

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.findings import FileReport
from fuzzoff.gate import GateTransition
from fuzzoff.gate.sections import link
from fuzzoff.modes import nav_state_name
from fuzzoff.timeline import Timeline

Row = dict[str, Any]


def _transition_row(tr: GateTransition) -> Row:
    return {
        "time_s": round(tr.t, 6),
        "source": "model",
        "what": tr.what,
        "message": tr.message,
        "see": link(tr.spec),
        "unverified": tr.unverified,
        "nav_state": tr.nav_state,
        "mode": nav_state_name(tr.nav_state) if tr.nav_state is not None else None,
        "action": tr.action,
        "reason": tr.reason,
        "recorded_nav_state": tr.recorded_nav_state,
        "earliest_s": None if tr.t_earliest is None else round(tr.t_earliest, 6),
        "seen_in": tr.seen_in,
    }


def _recorded_row(t: float, nav: int | None, armed: bool | None) -> Row:
    arming = "" if armed is None else (" armed" if armed else " disarmed")
    return {
        "time_s": round(t, 6),
        "source": "recorded",
        "what": "recorded",
        "message": f"{nav_state_name(nav)}{arming}",
        "see": None,
        "unverified": False,
        "nav_state": nav,
        "mode": nav_state_name(nav) if nav is not None else None,
        "armed": armed,
    }


def timeline_rows(timeline: Timeline, controllers: bool = True) -> list[Row]:
    """Model transitions and recorded mode changes of one vehicle, in time order."""
    rows = [
        _transition_row(tr) for tr in timeline.transitions if controllers or tr.what != "controller"
    ]
    rows += [_recorded_row(t, nav, armed) for t, nav, armed in timeline.recorded_modes]
    rows.sort(key=lambda r: (r["time_s"], r["source"] != "recorded"))
    return rows


def gate_report(
    path: str, settings: Settings, controllers: bool = True
) -> tuple[FileReport, dict[str, list[Row]]]:
    """Lint ``path`` with only the gate's own rule (OFB202) and every vehicle's timeline as
    rows (``controllers=False``: without the rows of the controller that runs)."""
    settings = settings.for_recording(path)
    # Only the gate's own rule: the timeline needs the model, not every check.
    settings = dataclasses.replace(
        settings,
        select=frozenset({"OFB202"}),
        ignore=frozenset(),
        per_file_ignores=(),
        discovery=None,
    )
    timelines: dict[str, Timeline] = {}
    report = lint_file(path, settings, timelines=timelines)
    rows = {v: timeline_rows(tl, controllers) for v, tl in sorted(timelines.items())}
    return report, rows
