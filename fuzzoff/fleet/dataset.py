"""The fleet table: a Parquet dataset with one row per recording and one per finding.

Layout (hive partitioning by the run's UTC date, so a query over the last week reads only that
week's files)::

    DIR/recordings/run_date=2026-11-24/part-20261124T021500Z-0.parquet
    DIR/findings/run_date=2026-11-24/part-20261124T021500Z-0.parquet

Every run appends parts under its own ``run_id`` (its UTC start, sortable as text); nothing is
rewritten. A recording is known by the SHA-256 of its content: a run skips the hashes the
dataset holds already (``known_hashes``), unless forced, in which case the recording gets a
newer row and readers take the latest row per hash (``latest``). Recordings whose lint did
not finish (crashed, timed out, fuzzoff failed) are not known: the next run tries them again.
"""

from __future__ import annotations

from collections.abc import Iterable
from datetime import UTC, date, datetime
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.dataset as ds
import pyarrow.parquet as pq

from fuzzoff import __version__
from fuzzoff.findings import Severity
from fuzzoff.fleet.task import LINTED, SKIPPED, Outcome
from fuzzoff.lean_dataclass import dataclass

RECORDINGS = "recordings"
FINDINGS = "findings"

RECORDING_SCHEMA = pa.schema(
    [
        ("run_id", pa.string()),
        ("path", pa.string()),
        ("sha256", pa.string()),
        ("size", pa.int64()),
        ("format", pa.string()),
        ("px4", pa.string()),
        ("px4_release", pa.string()),
        ("px4_source", pa.string()),
        ("vehicle", pa.string()),
        ("vehicle_source", pa.string()),
        ("start_time", pa.timestamp("us", tz="UTC")),
        ("duration_s", pa.float64()),
        ("events", pa.int64()),
        ("complete", pa.bool_()),
        ("status", pa.string()),
        ("errors", pa.int32()),
        ("warnings", pa.int32()),
        ("info", pa.int32()),
        ("lint_s", pa.float64()),
        ("fuzzoff_version", pa.string()),
        ("run_date", pa.date32()),
    ]
)
"""``px4``/``vehicle``: the profile the recording was judged with; ``px4_release``: the
release the recording names (null where it names none); ``*_source``: ``recording``,
``user`` or ``default``. ``status``: see ``fuzzoff.fleet.task``."""

FINDING_SCHEMA = pa.schema(
    [
        ("run_id", pa.string()),
        ("sha256", pa.string()),
        ("path", pa.string()),
        ("code", pa.string()),
        ("name", pa.string()),
        ("severity", pa.string()),
        ("message", pa.string()),
        ("time_s", pa.float64()),
        ("end_s", pa.float64()),
        ("vehicle_id", pa.string()),
        ("topic", pa.string()),
        ("index", pa.int64()),
        ("offset", pa.int64()),
        ("px4", pa.string()),
        ("px4_release", pa.string()),
        ("vehicle", pa.string()),
        ("start_time", pa.timestamp("us", tz="UTC")),
        ("run_date", pa.date32()),
    ]
)
"""``vehicle_id``: which vehicle of the recording (a MAVLink system id, a ROS namespace);
``vehicle``: its type. The profile and start time are repeated from the recording's row so
that the common queries need no join."""


class DatasetError(Exception):
    """The folder holds something that is not a fuzzoff dataset (one line)."""


@dataclass(frozen=True, slots=True)
class RunInfo:
    run_id: str
    day: date

    @classmethod
    def now(cls) -> RunInfo:
        moment = datetime.now(UTC)
        return cls(moment.strftime("%Y%m%dT%H%M%S%fZ"), moment.date())


def _table_dir(root: Path, name: str) -> Path:
    return root / name


def _dataset(root: Path, name: str, schema: pa.Schema) -> ds.Dataset | None:
    folder = _table_dir(root, name)
    if not folder.is_dir() or not any(folder.rglob("*.parquet")):
        return None
    try:
        return ds.dataset(folder, format="parquet", partitioning="hive", schema=schema)
    except (pa.ArrowInvalid, OSError) as exc:
        raise DatasetError(f"{folder}: not a fuzzoff dataset ({exc})") from None


def read(root: Path, name: str) -> pa.Table:
    """A whole table (empty, with its columns, when the dataset has none yet)."""
    schema = RECORDING_SCHEMA if name == RECORDINGS else FINDING_SCHEMA
    dataset = _dataset(root, name, schema)
    if dataset is None:
        return schema.empty_table()
    try:
        return dataset.to_table()
    except (pa.ArrowInvalid, OSError) as exc:
        raise DatasetError(f"{_table_dir(root, name)}: cannot be read ({exc})") from None


def known_hashes(root: Path) -> frozenset[str]:
    """The content hashes of the recordings a run need not lint again."""
    dataset = _dataset(root, RECORDINGS, RECORDING_SCHEMA)
    if dataset is None:
        return frozenset()
    try:
        table = dataset.to_table(columns=["sha256"], filter=pc.field("status") == LINTED)
    except (pa.ArrowInvalid, OSError) as exc:
        raise DatasetError(f"{_table_dir(root, RECORDINGS)}: cannot be read ({exc})") from None
    return frozenset(h for h in table.column("sha256").to_pylist() if h)


def latest(recordings: pa.Table, key: str = "sha256") -> pa.Table:
    """One row per recording: its newest (the newest ``run_id`` per ``key``; rows with a null
    key stay as they are)."""
    if recordings.num_rows == 0:
        return recordings
    ordered = recordings.sort_by([("run_id", "descending")])
    seen: set[str] = set()
    keep = []
    for i, value in enumerate(ordered.column(key).to_pylist()):
        if value is not None:
            if value in seen:
                continue
            seen.add(value)
        keep.append(i)
    return ordered.take(keep)


class Writer:
    """Appends a run's outcomes as parts of at most ``batch`` recordings (a run that stops
    half-way keeps what it wrote: the next run skips those)."""

    def __init__(self, root: Path, run: RunInfo, batch: int = 1000) -> None:
        self.root = root
        self.run = run
        self.batch = batch
        self.parts = 0
        self.recordings = 0
        self.findings = 0
        self._pending: list[Outcome] = []

    def add(self, outcome: Outcome) -> None:
        if outcome.status == SKIPPED or outcome.report is None:
            return
        self._pending.append(outcome)
        if len(self._pending) >= self.batch:
            self.flush()

    def flush(self) -> None:
        if not self._pending:
            return
        outcomes, self._pending = self._pending, []
        recordings = pa.Table.from_pylist(
            [self._recording_row(o) for o in outcomes], schema=RECORDING_SCHEMA
        )
        findings = pa.Table.from_pylist(list(self._finding_rows(outcomes)), schema=FINDING_SCHEMA)
        self._write(RECORDINGS, recordings)
        if findings.num_rows:
            self._write(FINDINGS, findings)
        self.parts += 1
        self.recordings += recordings.num_rows
        self.findings += findings.num_rows

    def _write(self, name: str, table: pa.Table) -> None:
        pq.write_to_dataset(
            table,
            str(_table_dir(self.root, name)),
            partition_cols=["run_date"],
            basename_template=f"part-{self.run.run_id}-{self.parts}-{{i}}.parquet",
            existing_data_behavior="overwrite_or_ignore",
        )

    def _recording_row(self, o: Outcome) -> dict[str, Any]:
        assert o.report is not None
        r = o.report
        counts = {s: 0 for s in Severity}
        for f in r.findings:
            counts[f.severity] += 1
        events = r.stats.get("events")
        duration = r.stats.get("duration_s")
        return {
            "run_id": self.run.run_id,
            "path": o.target,
            "sha256": o.sha256,
            "size": o.size,
            "format": r.format,
            "px4": r.profile.px4,
            "px4_release": r.profile.px4_release,
            "px4_source": r.profile.px4_source,
            "vehicle": r.profile.vehicle,
            "vehicle_source": r.profile.vehicle_source,
            "start_time": o.started,
            "duration_s": float(duration) if isinstance(duration, int | float) else None,
            "events": int(events) if isinstance(events, int) else None,
            "complete": r.complete,
            "status": o.status,
            "errors": counts[Severity.ERROR],
            "warnings": counts[Severity.WARNING],
            "info": counts[Severity.INFO],
            "lint_s": round(o.seconds, 6),
            "fuzzoff_version": __version__,
            "run_date": self.run.day,
        }

    def _finding_rows(self, outcomes: Iterable[Outcome]) -> Iterable[dict[str, Any]]:
        for o in outcomes:
            assert o.report is not None
            p = o.report.profile
            for f in o.report.findings:
                where = f.where
                yield {
                    "run_id": self.run.run_id,
                    "sha256": o.sha256,
                    "path": o.target,
                    "code": f.code,
                    "name": f.name,
                    "severity": f.severity.label,
                    "message": f.message,
                    "time_s": f.time_s,
                    "end_s": f.end_s,
                    "vehicle_id": f.vehicle,
                    "topic": where.topic if where is not None else None,
                    "index": where.index if where is not None else None,
                    "offset": where.offset if where is not None else None,
                    "px4": p.px4,
                    "px4_release": p.px4_release,
                    "vehicle": p.vehicle,
                    "start_time": o.started,
                    "run_date": self.run.day,
                }
