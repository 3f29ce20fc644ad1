"""A recording is read by what it holds, never by its name (issue 26 item 3).

Every format's intact recording, copied under a name in another case, with ``.active`` after
it, with another format's extension or with none, lints exactly as under its own name: the
same format, findings, exit status and stderr. An MCAP named ``FLIGHT.MCAP`` used to be read
as a damaged SQLite database (OFB001, exit 2), and a ``.DB3`` salvaged row by row.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import CORPORA, run_cli

RECORDINGS = {
    "tlog": CORPORA / "tlog" / "good_offboard.tlog",
    "ulog": CORPORA / "ulog" / "switch_rejected.ulg",
    "mcap": CORPORA / "stream" / "ofb104_good.mcap",
    "rosbag1": CORPORA / "damaged" / "chunked.bag",
    "rosbag2-sqlite3": CORPORA / "rosbag2" / "good_flight_sqlite3" / "good_flight_sqlite3.db3",
}
BAGS = {
    "rosbag2-sqlite3": CORPORA / "rosbag2" / "good_flight_sqlite3",
    "rosbag2-mcap": CORPORA / "rosbag2" / "stream_lost_mcap",
}
OTHER_EXTENSION = {
    ".tlog": ".ulg",
    ".ulg": ".mcap",
    ".mcap": ".db3",
    ".bag": ".tlog",
    ".db3": ".bag",
}


def names(path: Path) -> dict[str, str]:
    """The names a copy of ``path`` is given, by what they change."""
    return {
        "upper case": path.stem.upper() + path.suffix.upper(),
        ".active": path.name + ".active",
        "another format's extension": path.stem + OTHER_EXTENSION[path.suffix],
        "an unknown extension": path.stem + ".bin",
        "none": path.stem,
    }


def lint(path: Path) -> tuple[int, str, list[Any], str]:
    """Exit status, format, findings and stderr, with the path taken out of the messages."""
    result = run_cli(["lint", str(path), "--format", "json"])
    (report,) = json.loads(result.stdout)["files"]
    findings = json.loads(json.dumps(report["findings"]).replace(str(path), "PATH"))
    for finding in findings:
        finding.pop("file", None)
    return result.returncode, report["format"], findings, result.stderr.replace(str(path), "PATH")


CASES = [(fmt, how) for fmt in RECORDINGS for how in names(Path("x.tlog"))]


@pytest.mark.parametrize(("fmt", "how"), CASES)
def test_a_recording_under_any_name_reads_as_under_its_own(
    fmt: str, how: str, tmp_path: Path
) -> None:
    intact = RECORDINGS[fmt]
    copy = tmp_path / names(intact)[how]
    shutil.copyfile(intact, copy)
    code, detected, findings, stderr = lint(copy)
    assert detected == fmt
    assert (code, findings, stderr) == lint(intact)[0:1] + lint(intact)[2:]


@pytest.mark.parametrize(
    ("fmt", "how"), [(fmt, how) for fmt in BAGS for how in names(Path("x.db3"))]
)
def test_a_bags_data_file_under_any_name_reads_as_under_its_own(
    fmt: str, how: str, tmp_path: Path
) -> None:
    # The name metadata.yaml lists for it too, as a bag renamed by hand would be.
    intact = BAGS[fmt]
    bag = tmp_path / intact.name
    shutil.copytree(intact, bag)
    (data,) = (p for p in bag.iterdir() if p.name != "metadata.yaml")
    renamed = data.with_name(names(data)[how])
    data.rename(renamed)
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text().replace(data.name, renamed.name))
    expected = lint(intact)
    assert lint(bag)[:3] == expected[:3]
    code, detected, findings, _ = lint(renamed)  # the data file given, metadata.yaml beside it
    assert detected == fmt
    assert (code, findings) == (expected[0], expected[2])
