"""Findings a team has accepted: the configuration's ``suppressions`` (a recording, a code, a
time window, a reason) and a ``--baseline`` file of the findings an earlier lint reported.

Both act on a lint's ``Report`` once it is made, whatever ran it (this process, workers, a
cluster): a suppressed finding leaves ``FileReport.findings``, so it fails no run, and joins
``FileReport.suppressed`` with why, so the JSON and HTML reports still show it. A baseline
matches a finding by its recording and its SARIF fingerprint (rule, vehicle, topic and time
window: ``report.marks.marks``), which stays the same over re-lints and fuzzoff versions
where the finding did not change.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from fuzzoff import __version__
from fuzzoff.config import ConfigError, Settings
from fuzzoff.findings import FileReport, Finding, Report, Suppression
from fuzzoff.report.marks import marks

BASELINE_VERSION = 1


def apply_config(report: Report, settings_for: Callable[[str], Settings]) -> None:
    """Move each finding a ``suppressions`` entry of its recording's settings covers."""
    for file in report.files:
        entries = settings_for(file.path).suppressions
        if not entries:
            continue
        kept: list[Finding] = []
        for finding in file.findings:
            entry = next((e for e in entries if e.covers(finding)), None)
            if entry is None:
                kept.append(finding)
                continue
            why = Suppression("config", entry.reason, entry.source, entry.from_s, entry.to_s)
            file.suppressed.append((finding, why))
        file.findings = kept


def _key(recording: str, folder: Path) -> str:
    """A recording as a baseline names it: relative to the baseline's folder, ``/``-separated."""
    return Path(os.path.relpath(os.path.abspath(recording), os.path.abspath(folder))).as_posix()


def write_baseline(report: Report, path: Path) -> int:
    """Every finding of ``report`` into the baseline ``path`` (replaced); how many."""
    entries: list[dict[str, Any]] = []
    for file in report.files:
        recording = _key(file.path, path.parent)
        for finding, mark in zip(file.findings, marks(file.findings), strict=True):
            entries.append(
                {
                    "path": recording,
                    "fingerprint": mark,
                    "code": finding.code,
                    "time_s": None if finding.time_s is None else round(finding.time_s, 3),
                    "summary": finding.short,
                }
            )
    entries.sort(key=lambda e: (e["path"], e["code"], e["fingerprint"]))
    data = {
        "tool": "fuzzoff",
        "baseline": BASELINE_VERSION,
        "written_by": __version__,
        "findings": entries,
    }
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"--write-baseline {path}: {exc.strerror or exc}") from None
    return len(entries)


def read_baseline(path: Path) -> frozenset[tuple[str, str]]:
    """The baseline's (recording, fingerprint) pairs; a file that is no baseline is a usage
    error, not an empty baseline (which would fail the run on every old finding)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError(f"--baseline {path}: {exc.strerror or exc}") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise ConfigError(f"--baseline {path}: not JSON: {exc}") from None
    if not isinstance(data, dict) or data.get("tool") != "fuzzoff" or "findings" not in data:
        raise ConfigError(f"--baseline {path}: not a fuzzoff baseline (--write-baseline makes one)")
    if data.get("baseline") != BASELINE_VERSION:
        raise ConfigError(f"--baseline {path}: baseline version {data.get('baseline')!r} unknown")
    try:
        return frozenset((str(e["path"]), str(e["fingerprint"])) for e in data["findings"])
    except (KeyError, TypeError):
        raise ConfigError(f"--baseline {path}: an entry without path or fingerprint") from None


def apply_baseline(report: Report, known: frozenset[tuple[str, str]], path: Path) -> None:
    """Move each finding the baseline ``path`` holds (``known``, ``read_baseline``) out of the
    failing ones."""
    why = Suppression("baseline", "in the baseline", str(path))
    for file in report.files:
        recording = _key(file.path, path.parent)
        kept: list[Finding] = []
        for finding, mark in zip(file.findings, marks(file.findings), strict=True):
            if (recording, mark) in known:
                file.suppressed.append((finding, why))
            else:
                kept.append(finding)
        file.findings = kept


def suppressed_count(files: list[FileReport]) -> int:
    return sum(len(f.suppressed) for f in files)
