"""``lint --scheduler`` and ``fuzz --scheduler`` on a real ``dask.distributed`` LocalCluster with
two worker processes: the same findings as a plain lint, a worker killed mid-run, a recording
that kills every worker, one that hangs, URLs fetched by the workers, an incremental second run.
"""

from __future__ import annotations

import contextlib
import functools
import json
import shutil
import threading
import time
from collections.abc import Iterator
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest
from distributed import Client

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file
from fuzzoff.fleet.cluster import local_cluster, run_on_cluster
from fuzzoff.fleet.task import CRASHED, LINTED, TIMED_OUT
from tests import fleet_helpers
from tests.helpers import CORPORA, run_cli

TLOGS = CORPORA / "tlog"


@pytest.fixture(scope="module")
def client() -> Iterator[Any]:
    cluster = local_cluster(2)
    try:
        with Client(cluster) as c:
            yield c
    finally:
        # the LocalCluster's own view of its workers may have failed on a worker killed
        # twice in a row (``_two_workers``); its close re-raises that KeyError
        with contextlib.suppress(KeyError):
            cluster.close()


def _two_workers(client: Any) -> None:
    """Wait until the scheduler has both workers again (the nannies restart killed ones).
    Asked of the scheduler: ``Client.wait_for_workers`` asks the LocalCluster object, whose
    view of the workers stops updating when a restarted worker is killed again before the
    cluster saw it arrive (a KeyError in distributed's ``_update_worker_status``)."""
    deadline = time.monotonic() + 120
    while len(client.nthreads()) < 2:
        assert time.monotonic() < deadline, "the killed workers were not restarted in 120 s"
        time.sleep(0.2)


def _warm(client: Any) -> None:
    """Both workers up and past their first lint (its imports take seconds on a loaded
    machine, and the timeout tests time seconds)."""
    _two_workers(client)
    client.run(lint_file, str(TLOGS / "good_offboard.tlog"))


def _some(tmp_path: Path, *special: str) -> list[str]:
    """Three corpus tlogs and a copy of a good one under each special name."""
    chosen = ["good_offboard.tlog", "stream_lost_in_offboard.tlog", "truncated.tlog"]
    targets = [str(TLOGS / name) for name in chosen]
    for name in special:
        shutil.copy(TLOGS / "good_offboard.tlog", tmp_path / name)
        targets.append(str(tmp_path / name))
    return targets


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_scheduler_local_gives_the_findings_of_jobs(jobs: str) -> None:
    """The whole corpus, several recordings to a task (``test_fleet_batches``), beside the
    same ``--jobs``."""
    plain = run_cli(["lint", str(CORPORA), "--format", "json", "--jobs", jobs])
    dask_run = run_cli(
        ["lint", "--scheduler", "local", "--jobs", jobs, str(CORPORA), "--format", "json"]
    )
    assert plain.returncode == 2, "the corpus holds damaged recordings on purpose"
    assert dask_run.returncode == plain.returncode
    assert json.loads(dask_run.stdout) == json.loads(plain.stdout)
    assert dask_run.stderr == plain.stderr


def test_a_worker_killed_mid_run_the_run_finishes_and_the_recording_is_reported(
    client: Any, tmp_path: Path
) -> None:
    targets = _some(tmp_path, "victim.tlog")
    marker = tmp_path / "killed"
    lint = partial(fleet_helpers.kill_once, marker=str(marker))
    outcomes = run_on_cluster(client, targets, Settings(), lint=lint)
    assert marker.exists(), "a worker process was killed while linting the recording"
    assert [o.status for o in outcomes] == [LINTED] * 4
    victim = outcomes[-1].report
    assert victim is not None
    assert victim.to_json() == lint_file(targets[-1]).to_json()
    _two_workers(client)


def test_a_recording_that_kills_every_worker_is_its_ofb001_and_the_run_goes_on(
    client: Any, tmp_path: Path
) -> None:
    targets = _some(tmp_path, "crash.tlog")
    outcomes = run_on_cluster(client, targets, Settings(), lint=fleet_helpers.crash_or_hang)
    assert [o.status for o in outcomes] == [LINTED, LINTED, LINTED, CRASHED], [
        o.report.problems for o in outcomes if o.report
    ]
    for good, target in zip(outcomes[:3], targets[:3], strict=True):
        assert good.report is not None and good.report.to_json() == lint_file(target).to_json()
    crashed = outcomes[-1].report
    assert crashed is not None and not crashed.complete
    [finding] = crashed.findings
    assert finding.code == "OFB001"
    assert finding.message.startswith(f"{targets[-1]}: the lint did not finish")
    assert "worker process linting it died after" in finding.message
    _two_workers(client)


def test_a_recording_that_hangs_is_stopped_after_the_timeout(client: Any, tmp_path: Path) -> None:
    targets = _some(tmp_path, "hang.tlog")
    _warm(client)
    outcomes = run_on_cluster(
        client, targets, Settings(), lint=fleet_helpers.crash_or_hang, timeout_s=2.0
    )
    assert [o.status for o in outcomes] == [LINTED, LINTED, LINTED, TIMED_OUT]
    hung = outcomes[-1].report
    assert hung is not None
    [problem] = hung.problems
    assert problem.startswith(
        f"{targets[-1]}: the lint did not finish within 2 s (--timeout): stopped by ending its "
        "Dask worker tcp://127.0.0.1:"
    )
    assert problem.endswith(" (its nanny starts a new one)")
    _two_workers(client)
    # the restarted worker lints again
    again = run_on_cluster(client, targets[:3], Settings())
    assert [o.status for o in again] == [LINTED] * 3


def _one_task(targets: list[str]) -> list[tuple[int, ...]]:
    return [tuple(range(len(targets)))]


def _same_as_plain(outcomes: list[Any], targets: list[str], skip: int) -> None:
    for k, (outcome, target) in enumerate(zip(outcomes, targets, strict=True)):
        if k != skip:
            assert outcome.status == LINTED
            assert outcome.report.to_json() == lint_file(target).to_json()


def test_a_recording_that_kills_every_worker_in_a_batch_is_its_ofb001_alone(
    client: Any, tmp_path: Path
) -> None:
    targets = _some(tmp_path, "crash.tlog", "after.tlog")
    # the crash in the middle of one task of five recordings
    targets[3], targets[1] = targets[1], targets[3]
    outcomes = run_on_cluster(
        client, targets, Settings(), lint=fleet_helpers.crash_or_hang, tasks=_one_task(targets)
    )
    assert [o.status for o in outcomes] == [LINTED, CRASHED, LINTED, LINTED, LINTED]
    _same_as_plain(outcomes, targets, skip=1)
    crashed = outcomes[1].report
    assert crashed is not None and not crashed.complete
    [finding] = crashed.findings
    assert finding.code == "OFB001"
    assert finding.message.startswith(f"{targets[1]}: the lint did not finish: the Dask worker")
    _two_workers(client)


def test_a_worker_killed_once_mid_batch_the_batch_is_linted_elsewhere(
    client: Any, tmp_path: Path
) -> None:
    targets = _some(tmp_path, "victim.tlog", "after.tlog")
    marker = tmp_path / "killed"
    lint = partial(fleet_helpers.kill_once, marker=str(marker))
    outcomes = run_on_cluster(client, targets, Settings(), lint=lint, tasks=_one_task(targets))
    assert marker.exists(), "a worker process was killed while linting the batch"
    _same_as_plain(outcomes, targets, skip=-1)
    _two_workers(client)


def test_a_recording_that_hangs_in_a_batch_is_stopped_and_the_others_linted(
    client: Any, tmp_path: Path
) -> None:
    targets = _some(tmp_path, "hang.tlog", "after.tlog")
    targets[3], targets[1] = targets[1], targets[3]
    _warm(client)
    outcomes = run_on_cluster(
        client,
        targets,
        Settings(),
        lint=fleet_helpers.crash_or_hang,
        timeout_s=2.0,
        tasks=_one_task(targets),
    )
    assert [o.status for o in outcomes] == [LINTED, TIMED_OUT, LINTED, LINTED, LINTED]
    _same_as_plain(outcomes, targets, skip=1)
    hung = outcomes[1].report
    assert hung is not None
    [problem] = hung.problems
    assert problem.startswith(f"{targets[1]}: the lint did not finish within 2 s (--timeout)")
    _two_workers(client)


def test_the_timeout_is_per_recording_not_per_batch(client: Any, tmp_path: Path) -> None:
    """Four recordings of 1.2 s each in one task: 4.8 s in all, past a 3 s timeout, and
    none of them past it alone."""
    slow = [f"slow_{k}.tlog" for k in range(4)]
    targets = _some(tmp_path, *slow)
    _warm(client)
    outcomes = run_on_cluster(
        client,
        targets,
        Settings(),
        lint=fleet_helpers.crash_or_hang,
        timeout_s=3.0,
        tasks=_one_task(targets),
    )
    _same_as_plain(outcomes, targets, skip=-1)


def test_an_incremental_second_run_lints_nothing_new(client: Any, tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    for name in ("good_offboard.tlog", "stream_lost_in_offboard.tlog", "truncated.tlog"):
        shutil.copy(TLOGS / name, logs / name)
    out = tmp_path / "fleet"
    address = client.scheduler.address
    args = ["lint", "--scheduler", address, str(logs), "--format", "parquet", "--output", str(out)]
    first = run_cli(args)
    assert first.returncode == 2, first.stderr  # truncated.tlog
    assert first.stdout.startswith("fuzzoff: 3 recordings: 3 linted;")
    second = run_cli(args)
    assert second.returncode == 0
    assert second.stdout.startswith("fuzzoff: 3 recordings: 0 linted; 3 skipped")
    assert second.stderr == ""
    shutil.copy(TLOGS / "keepalive_gap_0_7s.tlog", logs / "renamed_new_flight.tlog")
    shutil.copy(TLOGS / "good_offboard.tlog", logs / "same_flight_again.tlog")
    third = run_cli(args)
    assert third.stdout.startswith("fuzzoff: 5 recordings: 1 linted; 4 skipped")
    forced = run_cli([*args, "--force"])
    assert forced.stdout.startswith("fuzzoff: 5 recordings: 5 linted;")


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:
        pass


class _Server(ThreadingHTTPServer):
    def handle_error(self, request: Any, client_address: Any) -> None:
        """A client that closes early (fsspec reads what it needs) is not news here."""


@pytest.fixture
def http_root(tmp_path: Path) -> Iterator[tuple[str, Path]]:
    """A local HTTP server (Python's http.server in a thread) over a folder of recordings."""
    root = tmp_path / "served"
    shutil.copytree(TLOGS, root / "tlog", ignore=shutil.ignore_patterns("*.json", "*.py"))
    shutil.copytree(CORPORA / "rosbag2" / "good_flight_sqlite3", root / "bags" / "flight")
    handler = functools.partial(_Quiet, directory=str(root))
    server = _Server(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/", root
    finally:
        server.shutdown()
        server.server_close()


def test_urls_are_fetched_by_the_workers_with_the_findings_of_local_files(
    client: Any, http_root: tuple[str, Path]
) -> None:
    url, root = http_root
    address = client.scheduler.address
    remote = run_cli(["lint", "--scheduler", address, url, "--format", "json"])
    local = run_cli(["lint", str(root), "--format", "json"])
    assert remote.returncode == local.returncode == 2  # tlog/truncated.tlog
    paths = [f["path"] for f in json.loads(remote.stdout)["files"]]
    assert f"{url}bags/flight" in paths, "a bag folder is one recording, fetched whole"
    assert remote.stdout.replace(url, f"{root}/") == local.stdout
    assert remote.stderr.replace(url, f"{root}/") == local.stderr


def test_fuzz_seeds_on_the_cluster_report_as_the_same_campaign_run_here(client: Any) -> None:
    args = [
        "fuzz", "--seeds", "0-1", "--property", "explained", "--ignore", "OFB103,OFB101",
        "--examples", "200", "--px4", "1.15", "--vehicle", "mc", "--no-save", "--format", "json",
    ]  # fmt: skip
    here = json.loads(run_cli(args).stdout)
    there = run_cli([*args, "--scheduler", client.scheduler.address])
    assert there.returncode == 1
    on_cluster = json.loads(there.stdout)
    assert on_cluster["campaign"] == here["campaign"]
    assert on_cluster["campaign"]["seeds"] == [0, 1]

    def stable(report: dict[str, Any]) -> list[tuple[Any, ...]]:
        """What does not depend on time (shrinking stops after a time limit on a busy
        machine, so the shrunk scenario can differ)."""
        return [
            (p["property"], p["failed"], p["examples"], _found_by_seed_0(p["problems"]))
            for p in report["properties"]
        ]

    assert stable(on_cluster) == stable(here) == [("explained", True, 400, True)]


def _found_by_seed_0(problems: list[str]) -> bool:
    return any(p.startswith("found by seed 0 (fuzzoff fuzz --seed 0)") for p in problems)
