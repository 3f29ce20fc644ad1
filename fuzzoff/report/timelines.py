"""Lint with the per-vehicle timelines the HTML report plots (``--format html``).

The timelines go into ``FileReport.extras``: ``timelines`` (vehicle -> ``Timeline``) and
``loss_timeouts`` (vehicle -> (seconds, where the value came from)).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from fuzzoff.config import Settings
from fuzzoff.engine import Timeline, lint_file, lint_paths
from fuzzoff.findings import FileReport, Report
from fuzzoff.gate import GateModel
from fuzzoff.profiles import Profile


def loss_timeout(timeline: Timeline, profile: Profile, settings: Settings) -> tuple[float, str]:
    """COM_OF_LOSS_T as the gate used it, and where the value came from.

    An engine that copies the gate's final ``loss_timeout`` and ``recorded_params`` onto the
    timeline gives the recording's own value; without them the value is ``--param`` /
    configuration, else the profile's default (what the gate model starts from). Before 1.11
    the timeout is a fixed 500 ms whatever COM_OF_LOSS_T says (gate spec 2.3).
    """
    recorded = getattr(timeline, "recorded_params", None) or {}
    value = getattr(timeline, "loss_timeout", None)
    if not isinstance(value, int | float):
        value = GateModel(profile, settings.params).loss_timeout
    if profile.release.fixed_loss_s is not None:
        return float(value), "fixed in PX4 before 1.11"  # COM_OF_LOSS_T is not the timeout
    if "COM_OF_LOSS_T" in settings.params:
        return float(value), settings.param_origin("COM_OF_LOSS_T")
    if "COM_OF_LOSS_T" in recorded:
        return float(value), "from the recording"
    return float(value), f"PX4 {profile.px4} default"


def lint_one(path: str | Path, settings: Settings) -> FileReport:
    settings = settings.for_recording(path)
    timelines: dict[str, Timeline] = {}
    report = lint_file(path, settings, timelines=timelines, plot_data=True)
    report.extras["timelines"] = timelines
    report.extras["loss_timeouts"] = {
        vehicle: loss_timeout(tl, report.profile, settings) for vehicle, tl in timelines.items()
    }
    return report


def lint_with_timelines(
    paths: Sequence[str | Path], settings: Settings, *, jobs: int = 1
) -> Report:
    """Like ``engine.lint_paths`` but every file report carries its timelines."""
    return lint_paths(paths, settings, jobs=jobs, lint=lint_one)
