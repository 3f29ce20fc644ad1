"""The fleet features that need no cluster: fsspec inputs (the memory filesystem), the Parquet
dataset read back by DuckDB with the queries of docs/fleet.md, the fleet page, merged fuzz seeds,
and the usage lines."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tempfile
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import duckdb
import fsspec
import pytest

from fuzzoff.config import Settings
from fuzzoff.events import ControlMode, VehicleStatus
from fuzzoff.fleet.fuzz_run import merge, parse_seeds
from fuzzoff.fleet.inputs import content_hash
from fuzzoff.fleet.task import lint_target
from fuzzoff.formats import find_recordings
from fuzzoff.fuzz.campaign import CampaignConfig, CampaignResult, PropertyResult
from fuzzoff.fuzz.scenario import Scenario
from tests.helpers import CORPORA, ROOT, run_cli

TLOGS = CORPORA / "tlog"
DOC = ROOT / "docs" / "fleet.md"


@pytest.fixture
def memory_logs() -> Iterator[str]:
    """Recordings in fsspec's memory filesystem: tlogs, a ULog, and a ROS 2 bag folder."""
    fs = fsspec.filesystem("memory")
    root = f"/fleet-{id(fs)}-logs"
    for name in ("good_offboard.tlog", "truncated.tlog"):
        fs.pipe(f"{root}/night/{name}", (TLOGS / name).read_bytes())
    fs.pipe(f"{root}/night/sd/LOG001.ULG", (CORPORA / "ulog" / "good_offboard.ulg").read_bytes())
    bag = CORPORA / "rosbag2" / "good_flight_sqlite3"
    for f in bag.iterdir():
        fs.pipe(f"{root}/night/bag/{f.name}", f.read_bytes())
    fs.pipe(f"{root}/night/notes.txt", b"not a recording")
    try:
        yield f"memory://{root}"
    finally:
        fs.rm(root, recursive=True)


def _local_copy(tmp_path: Path) -> Path:
    night = tmp_path / "night"
    (night / "sd").mkdir(parents=True)
    for name in ("good_offboard.tlog", "truncated.tlog"):
        shutil.copy(TLOGS / name, night / name)
    shutil.copy(CORPORA / "ulog" / "good_offboard.ulg", night / "sd" / "LOG001.ULG")
    shutil.copytree(CORPORA / "rosbag2" / "good_flight_sqlite3", night / "bag")
    return night


def test_a_memory_url_is_searched_and_linted_as_the_same_local_folder(
    memory_logs: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    remote = run_cli(["lint", f"{memory_logs}/night/", "--format", "json"])
    local = run_cli(["lint", str(_local_copy(tmp_path)), "--format", "json"])
    paths = [f["path"] for f in json.loads(remote.stdout)["files"]]
    assert paths == [
        f"{memory_logs}/night/bag",
        f"{memory_logs}/night/good_offboard.tlog",
        f"{memory_logs}/night/sd/LOG001.ULG",
        f"{memory_logs}/night/truncated.tlog",
    ]
    assert remote.returncode == local.returncode == 2
    local_root = str(tmp_path / "night")
    assert json.loads(remote.stdout.replace(f"{memory_logs}/night", local_root)) == json.loads(
        local.stdout
    )
    assert remote.stderr.replace(f"{memory_logs}/night", local_root) == local.stderr
    assert list(scratch.iterdir()) == [], "every fetched copy is removed after its lint"


def test_a_glob_url_takes_its_matches(memory_logs: str) -> None:
    result = run_cli(["lint", f"{memory_logs}/night/*.tlog", "--format", "json"])
    paths = [f["path"] for f in json.loads(result.stdout)["files"]]
    night = f"{memory_logs}/night"
    assert paths == [f"{night}/good_offboard.tlog", f"{night}/truncated.tlog"]


def test_a_recording_that_cannot_be_fetched_is_its_ofb001(memory_logs: str) -> None:
    outcome = lint_target(f"{memory_logs}/night/gone.tlog", Settings())
    assert outcome.report is not None and not outcome.report.complete
    assert outcome.report.problems == [f"{memory_logs}/night/gone.tlog: cannot fetch: not found"]
    assert [f.code for f in outcome.report.findings] == ["OFB001"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["memory://fleet-nothing-here/"], "no such recording or folder: memory://fleet-nothing"),
        (["nope://bucket/x.ulg"], "nope://bucket/x.ulg: Protocol not known: nope"),
        ([str(TLOGS), "--timeout", "5"], "--timeout needs --scheduler"),
        ([str(TLOGS), "--force"], "--force applies to --format parquet"),
        ([str(TLOGS), "--format", "parquet"], "--format parquet needs --output DIR"),
        ([str(TLOGS), "--scheduler", "local", "--timeout", "0"], "--timeout 0: expected seconds"),
    ],
)
def test_fleet_usage_mistakes_are_one_line_and_exit_2(args: list[str], message: str) -> None:
    result = run_cli(["lint", *args])
    assert result.returncode == 2
    assert result.stderr.startswith(f"error: {message}"), result.stderr
    assert len(result.stderr.splitlines()) == 1


def test_scheduler_without_the_fleet_extra_is_one_usage_line(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "distributed" else real(name)
    )
    result = run_cli(["lint", str(TLOGS), "--scheduler", "local"])
    assert result.returncode == 2
    assert result.stderr == "error: --scheduler needs distributed: pip install 'fuzzoff[fleet]'\n"


def test_the_lint_core_needs_none_of_the_fleet_extra(tmp_path: Path) -> None:
    """A plain lint with dask, distributed, fsspec and pyarrow unimportable."""
    script = (
        "import sys\n"
        "for name in ('dask', 'distributed', 'fsspec', 'pyarrow', 'aiohttp'):\n"
        "    sys.modules[name] = None\n"
        "from fuzzoff.cli import main\n"
        f"sys.exit(main(['lint', {str(TLOGS / 'good_offboard.tlog')!r}, '--format', 'json']))\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["files"][0]["format"] == "tlog"


@pytest.fixture(scope="module")
def corpus_dataset(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, object]]:
    """The corpus linted into a dataset named ``fleet`` (as the docs' queries call it), and
    the same lint's JSON report."""
    root = tmp_path_factory.mktemp("dataset")
    result = run_cli(["lint", str(CORPORA), "--format", "parquet", "--output", str(root / "fleet")])
    assert result.returncode == 2, result.stderr  # the corpus's damaged files
    report = json.loads(run_cli(["lint", str(CORPORA), "--format", "json"]).stdout)
    return root, report


def _queries() -> list[str]:
    return re.findall(r"```sql\n(.*?)```", DOC.read_text(), re.S)


def test_the_dataset_reads_back_in_duckdb_as_the_json_report(
    corpus_dataset: tuple[Path, dict[str, object]],
) -> None:
    root, report = corpus_dataset
    files = report["files"]
    assert isinstance(files, list)
    con = duckdb.connect()
    rec = f"read_parquet('{root}/fleet/recordings/**/*.parquet', hive_partitioning = true)"
    rows = con.sql(f"SELECT path, format, complete, errors, warnings, info FROM {rec}").fetchall()
    expected = []
    for f in files:
        n = Counter(x["severity"] for x in f["findings"])
        expected.append(
            (f["path"], f["format"], f["complete"], n["error"], n["warning"], n["info"])
        )
    assert sorted(rows) == sorted(expected)
    found = f"read_parquet('{root}/fleet/findings/**/*.parquet', hive_partitioning = true)"
    codes = con.sql(f"SELECT code, count(*) FROM {found} GROUP BY code").fetchall()
    assert dict(codes) == Counter(x["code"] for f in files for x in f["findings"])
    dates = con.sql(f"SELECT DISTINCT run_date FROM {rec}").fetchall()
    assert len(dates) == 1, "partitioned by the run's date"


def test_the_three_queries_in_the_docs_run_on_the_dataset(
    corpus_dataset: tuple[Path, dict[str, object]], monkeypatch: pytest.MonkeyPatch
) -> None:
    root, report = corpus_dataset
    monkeypatch.chdir(root)
    queries = _queries()
    assert len(queries) == 3
    by_release, worst, weekly = (duckdb.connect().sql(q).fetchall() for q in queries)
    assert by_release and all(n >= 1 for *_, n, _ in by_release)
    assert len(worst) == 10 and worst[0][5] >= worst[-1][5], "most errors first"
    files = report["files"]
    assert isinstance(files, list)
    # one row per recording's content: byte-identical copies (the damage corpus keeps intact
    # recordings under other names) are one flight
    contents = {content_hash(Path(str(f["path"])))[0] for f in files}
    assert sum(flights for _, flights, _ in weekly) == len(contents)


def test_a_second_run_without_force_lints_nothing(
    corpus_dataset: tuple[Path, dict[str, object]],
) -> None:
    root, _ = corpus_dataset
    out = root / "fleet"
    again = run_cli(["lint", str(TLOGS), "--format", "parquet", "--output", str(out)])
    assert again.returncode == 0
    n = len(find_recordings(TLOGS))
    assert again.stdout.startswith(f"fuzzoff: {n} recordings: 0 linted; {n} skipped")


def test_the_fleet_page_shows_the_views_and_escapes_recording_text(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    hostile = "<img src=x onerror=alert(1)>.tlog"
    shutil.copy(TLOGS / "stream_lost_in_offboard.tlog", logs / hostile)
    shutil.copy(TLOGS / "truncated.tlog", logs / "truncated.tlog")
    out = tmp_path / "fleet"
    run_cli(["lint", str(logs), "--format", "parquet", "--output", str(out)])
    shutil.copy(TLOGS / "good_offboard.tlog", logs / "next_night.tlog")
    run_cli(["lint", str(logs), "--format", "parquet", "--output", str(out)])
    result = run_cli(["fleet", str(out)])
    assert result.returncode == 0, result.stderr
    page = (out / "fleet.html").read_text()
    for title in (
        "What changed since the last run",
        "Findings per rule per week",
        "Per PX4 release",
        "Per vehicle type",
        "The worst recordings",
    ):
        assert f">{title}</h2>" in page
    assert "<script" not in page and "<img" not in page
    assert "&lt;img src=x onerror=alert(1)&gt;.tlog" in page
    assert "Content-Security-Policy" in page and "http://" not in page.split("</head>")[1]
    links = re.findall(r'href="(reports/[0-9a-f]{16}\.html)"', page)
    assert len(links) == 2, "the two recordings with errors link to their own reports"
    for link in links:
        own = (out / link).read_text()
        assert "<title>fuzzoff report</title>" in own
    assert "OFB103" in page and "OFB001" in page


def test_seeds_are_parsed_as_ranges_and_lists() -> None:
    assert parse_seeds("0-3") == (0, 1, 2, 3)
    assert parse_seeds("7, 3,5-6,3") == (7, 3, 5, 6)
    for bad in ("3-1", "x", "1-", ""):
        with pytest.raises(Exception, match="--seeds"):
            parse_seeds(bad)


def _result(seed: int, examples: int, scenario: Scenario | None) -> CampaignResult:
    r = PropertyResult("explained", "every hazard is explained", examples=examples)
    if scenario is not None:
        r.failed, r.counterexample, r.problems = True, scenario, [f"hazard (seed {seed})"]
        r.failed_examples = 1
    return CampaignResult(CampaignConfig(seed=seed, properties=("explained",)), [r])


def test_fuzz_seeds_merge_with_counterexamples_deduplicated_by_content() -> None:
    def scenario(gap: float) -> Scenario:
        events = (VehicleStatus(t=0.0, nav_state=14, armed=True), ControlMode(t=gap))
        return Scenario(px4="1.15", vehicle="mc", transport="ros2", events=events)

    seeds = [3, 4, 5, 6]
    results = [
        _result(3, 10, None),
        _result(4, 20, scenario(0.5)),
        _result(5, 30, scenario(0.5)),  # the same shrunk content as seed 4's
        _result(6, 40, scenario(1.5)),
    ]
    config = CampaignConfig(seed=3, seeds=tuple(seeds), properties=("explained",))
    [merged] = merge(config, results, seeds).results
    assert merged.examples == 100 and merged.failed and merged.failed_examples == 3
    assert merged.counterexample == scenario(0.5), "the lowest failing seed's"
    assert merged.problems[:2] == [
        "hazard (seed 4)",
        "found by seed 4 (fuzzoff fuzz --seed 4), and by 1 other seed shrunk to the same",
    ]
    [other] = merged.problems[2:]
    assert other.startswith("another counterexample (found by seed 6 (fuzzoff fuzz --seed 6)): ")
    assert other.endswith(": hazard (seed 6)")


def test_fuzz_seeds_run_as_one_campaign_from_the_command_line() -> None:
    common = [
        "fuzz", "--property", "explained", "--ignore", "OFB103,OFB101", "--examples", "50",
        "--px4", "1.15", "--vehicle", "mc", "--no-save", "--format", "json",
    ]  # fmt: skip
    merged = run_cli([*common, "--seeds", "0-2"])
    assert merged.returncode == 1
    report = json.loads(merged.stdout)
    assert report["campaign"]["seeds"] == [0, 1, 2]
    [prop] = report["properties"]
    assert prop["examples"] == 150 and prop["failed"]
    assert any(p.startswith("found by seed ") for p in prop["problems"])
