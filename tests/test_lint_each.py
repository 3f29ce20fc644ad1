"""One way to run a local lint (issue 27): the recordings are found and their settings resolved
once (``plan_lint``, or the command), then ``lint_each`` lints them in order, here with a
progress watch or in worker processes, whatever the reports asked for."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from fuzzoff.config import load_settings
from fuzzoff.engine import lint_each, lint_file, lint_file_with_timelines, lint_paths, plan_lint
from tests.helpers import CORPORA

TLOGS = CORPORA / "tlog"
GAP = TLOGS / "stream_lost_in_offboard.tlog"


def test_each_recording_is_watched_while_it_is_linted() -> None:
    plan = plan_lint([TLOGS])
    seen: dict[str, list[float]] = {}

    @contextmanager
    def watch(path: str) -> Iterator[object]:
        seen[path] = []
        yield seen[path].append

    for lint in (lint_file, lint_file_with_timelines):
        seen.clear()
        report = lint_each(plan, lint=lint, watch=watch)
        assert [f.path for f in report.files] == [path for path, _ in plan]
        assert list(seen) == [path for path, _ in plan]
        assert all(fractions and fractions[-1] == 1.0 for fractions in seen.values())


def test_a_watched_lint_and_worker_processes_give_the_same_reports() -> None:
    plan = plan_lint([TLOGS])[:3]
    here = lint_each(plan, watch=None)
    workers = lint_each(plan, jobs=2)
    assert [f.to_json() for f in workers.files] == [f.to_json() for f in here.files]
    assert [f.to_json() for f in lint_paths([TLOGS]).files] == [
        f.to_json() for f in lint_each(plan_lint([TLOGS])).files
    ]


def test_each_recording_is_planned_with_its_nearest_configuration(tmp_path: Path) -> None:
    quiet = tmp_path / "quiet"
    quiet.mkdir()
    shutil.copy(GAP, quiet / "a.tlog")
    shutil.copy(GAP, tmp_path / "b.tlog")
    (quiet / "fuzzoff.toml").write_text('ignore = ["OFB101"]\n')
    settings = load_settings(tmp_path, per_recording=True)
    plan = dict(plan_lint([tmp_path], settings))
    a, b = plan[str(quiet / "a.tlog")], plan[str(tmp_path / "b.tlog")]
    assert "OFB101" in a.ignore and "OFB101" not in b.ignore
    assert a.discovery is None and b.discovery is None  # resolved: nothing left to look up
    codes = {f.path: {x.code for x in f.findings} for f in lint_each(list(plan.items())).files}
    assert (
        "OFB101" not in codes[str(quiet / "a.tlog")] and "OFB101" in codes[str(tmp_path / "b.tlog")]
    )
