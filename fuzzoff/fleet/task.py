"""Lint one recording, local or at a URL: the unit of work a Dask task (or a process) runs.

The lint itself is ``fuzzoff.lint_file`` (or, for the HTML report,
``engine.lint_file_with_timelines``), so a fleet run gives exactly the findings, problems and
exit status of a plain lint. Around it: fetching a URL into a temporary folder, the content hash
the Parquet dataset is keyed by, the skip of a recording the dataset already holds, and the
wall-clock start time.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Collection
from datetime import datetime
from pathlib import Path

from fuzzoff.catalog import get_rule
from fuzzoff.config import Settings
from fuzzoff.engine import lint_file, resolve_profile
from fuzzoff.findings import FileReport, Finding, Severity
from fuzzoff.fleet import is_url
from fuzzoff.fleet.inputs import FetchError, content_hash, fetched
from fuzzoff.fleet.wallclock import start_time
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.recording import RecordingInfo, path_text

Lint = Callable[[str, Settings], FileReport]

LINTED = "linted"
SKIPPED = "skipped"
CRASHED = "crashed"
TIMED_OUT = "timed out"
FAILED = "failed"
"""``Outcome.status``: fuzzoff's lint ran to its end (``linted``, whatever it found), the
dataset held the recording already (``skipped``), or the lint did not end: its worker died
(``crashed``), it ran past ``--timeout`` (``timed out``), or fuzzoff raised (``failed``)."""


@dataclass(slots=True)
class Outcome:
    """What became of one recording in a fleet run."""

    target: str
    """The recording as named to the user: a path as a plain lint writes it, or a URL."""
    report: FileReport | None
    """None when skipped."""
    status: str = LINTED
    sha256: str | None = None
    size: int | None = None
    started: datetime | None = None
    """The recording's own wall-clock start (UTC), where it has one."""
    seconds: float = 0.0
    """Time the worker spent on it (fetch, hash and lint)."""


def lint_target(
    target: str,
    settings: Settings,
    *,
    lint: Lint = lint_file,
    known: Collection[str] = (),
    record: bool = False,
) -> Outcome:
    """Lint ``target`` (a path or URL). ``record`` adds the hash, size and start time of the
    dataset's row; a recording whose hash is in ``known`` is skipped without linting."""
    t0 = time.perf_counter()
    if is_url(target):
        # a fetched copy is judged with the command's configuration, not one found near the
        # temporary folder it is fetched into
        settings = dataclasses.replace(settings, discovery=None)
        try:
            with fetched(target) as local:
                outcome = _lint_local(local, target, settings, lint, known, record)
        except FetchError as exc:
            outcome = Outcome(target, failed_report(target, str(exc), settings))
    else:
        outcome = _lint_local(Path(target), target, settings, lint, known, record)
    outcome.seconds = time.perf_counter() - t0
    return outcome


def _lint_local(
    local: Path,
    target: str,
    settings: Settings,
    lint: Lint,
    known: Collection[str],
    record: bool,
) -> Outcome:
    sha256 = size = None
    if record or known:
        sha256, size = content_hash(local)
        if sha256 is not None and sha256 in known:
            return Outcome(target, None, SKIPPED, sha256, size)
    report = lint(str(local), settings)
    if str(local) != target:
        report = renamed(report, path_text(local), target)
    started = start_time(local, report.format) if record else None
    return Outcome(target, report, LINTED, sha256, size, started)


def renamed(report: FileReport, local: str, target: str) -> FileReport:
    """The report of a fetched copy under the recording's own name (the URL): the temporary
    path appears in the report's path, its problem lines and OFB001 messages."""
    report.path = target
    report.problems = [p.replace(local, target) for p in report.problems]
    report.malformed = [p.replace(local, target) for p in report.malformed]
    report.findings = [
        dataclasses.replace(f, message=f.message.replace(local, target))
        if local in f.message
        else f
        for f in report.findings
    ]
    notes = report.stats.get("notes")
    if isinstance(notes, list):
        report.stats["notes"] = [str(n).replace(local, target) for n in notes]
    return report


def failed_report(target: str, what: str, settings: Settings) -> FileReport:
    """The report of a recording fuzzoff could not lint at all, as ``lint_file`` writes one
    for a file it cannot open: OFB001, incomplete."""
    name = path_text(target)
    line = f"{name}: {what}"
    report = FileReport(name, "unknown", resolve_profile(RecordingInfo(name, "?"), settings))
    report.complete = False
    report.problems.append(line)
    report.findings.append(Finding("OFB001", get_rule("OFB001").name, Severity.ERROR, line))
    return report
