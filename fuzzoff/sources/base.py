"""``from fuzzoff.sources.base import RecordingInfo`` as the README's Python API once showed it:
the same classes as ``fuzzoff.recording``."""

from __future__ import annotations

from fuzzoff.recording import RecordingInfo, Source, SourceError, SourceProblem

__all__ = ["RecordingInfo", "Source", "SourceError", "SourceProblem"]
