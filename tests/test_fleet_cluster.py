"""``lint --scheduler`` and ``fuzz --scheduler`` on a real ``dask.distributed`` LocalCluster with
two worker processes: the same findings as a plain lint, a worker killed mid-run, a recording
that kills every worker, one that hangs, URLs fetched by the workers, an incremental second run.
"""

from __future__ import annotations

import functools
import json
import shutil
import threading
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
    with local_cluster(2) as cluster, Client(cluster) as c:
        yield c


def _some(tmp_path: Path, *special: str) -> list[str]:
    """Three corpus tlogs and a copy of a good one under each special name."""
    chosen = ["good_offboard.tlog", "stream_lost_in_offboard.tlog", "truncated.tlog"]
    targets = [str(TLOGS / name) for name in chosen]
    for name in special:
        shutil.copy(TLOGS / "good_offboard.tlog", tmp_path / name)
        targets.append(str(tmp_path / name))
    return targets


def test_scheduler_local_gives_the_findings_of_a_plain_lint() -> None:
    plain = run_cli(["lint", str(CORPORA), "--format", "json"])
    dask_run = run_cli(["lint", "--scheduler", "local", str(CORPORA), "--format", "json"])
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
    client.wait_for_workers(2, timeout=30)


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
    client.wait_for_workers(2, timeout=30)


def test_a_recording_that_hangs_is_stopped_after_the_timeout(client: Any, tmp_path: Path) -> None:
    targets = _some(tmp_path, "hang.tlog")
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
    client.wait_for_workers(2, timeout=30)
    # the restarted worker lints again
    again = run_on_cluster(client, targets[:3], Settings())
    assert [o.status for o in again] == [LINTED] * 3


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
