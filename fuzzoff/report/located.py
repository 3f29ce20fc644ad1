"""What the one-line-per-finding formats (``github``, ``rdjson``, ``gitlab``, ``json-lines``)
share: each finding with its recording, its path as a CI service matches it against the
repository, and its fingerprint (the SARIF one: ``marks.marks``)."""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterator
from pathlib import Path

from fuzzoff.findings import FileReport, Finding, Report
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.report.marks import marks


@dataclass(frozen=True, slots=True)
class Located:
    """One finding of one recording."""

    file: FileReport
    finding: Finding
    path: str
    """The recording's path relative to the working folder (``/``-separated), as CI services
    name a repository's files; absolute where it lies outside."""
    mark: str
    """The SARIF ``partialFingerprints`` value: rule, vehicle, topic, time window."""

    @property
    def fingerprint(self) -> str:
        """The SARIF fingerprint with the path: unique in a report of many recordings, and the
        same on the next lint of the same recording."""
        return hashlib.sha256(f"{self.path}\0{self.mark}".encode()).hexdigest()[:32]


def repo_path(path: str, root: Path | None = None) -> str:
    """``path`` relative to ``root`` (the working folder) where it lies under it."""
    resolved = Path(os.path.abspath(path))
    try:
        return resolved.relative_to(Path(os.path.abspath(root or Path.cwd()))).as_posix()
    except ValueError:
        return resolved.as_posix()


def located(report: Report, root: Path | None = None) -> Iterator[Located]:
    """Every finding of the report, recording by recording, in report order."""
    for file in report.files:
        path = repo_path(file.path, root)
        for finding, mark in zip(file.findings, marks(file.findings), strict=True):
            yield Located(file, finding, path, mark)
