"""A bag split over several data files is one recording, with or without its metadata.yaml."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from ruamel.yaml import YAML

from fuzzoff.events import ControlMode, Event
from fuzzoff.formats.rosbag2.writer import write_rosbag2
from tests.ros2_samples import read_all


def _split_bag(tmp_path: Path, storage: str) -> tuple[Path, list[Event]]:
    """Two data files, the second continuing the first (as ``ros2 bag record --max-bag-size``)."""
    events: list[Event] = [ControlMode(t=0.05 * k, position=True) for k in range(200)]
    first = write_rosbag2(tmp_path / "a", events[:100], storage=storage)  # type: ignore[arg-type]
    second = write_rosbag2(
        tmp_path / "b",
        [ControlMode(t=e.t - 5.0, position=True) for e in events[100:]],
        storage=storage,  # type: ignore[arg-type]
        start_ns=1_700_000_005_000_000_000,
    )
    suffix = ".db3" if storage == "sqlite3" else ".mcap"
    bag = tmp_path / "bag"
    bag.mkdir()
    shutil.copy(next(first.glob(f"*{suffix}")), bag / f"bag_0{suffix}")
    shutil.copy(next(second.glob(f"*{suffix}")), bag / f"bag_1{suffix}")
    yaml = YAML()
    meta = yaml.load((first / "metadata.yaml").read_text())
    info = meta["rosbag2_bagfile_information"]
    info["relative_file_paths"] = [f"bag_0{suffix}", f"bag_1{suffix}"]
    info["files"] = []
    with (bag / "metadata.yaml").open("w") as fh:
        yaml.dump(meta, fh)
    return bag, events


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_split_bag_reads_as_one_recording(tmp_path: Path, storage: str) -> None:
    bag, events = _split_bag(tmp_path, storage)
    source, read = read_all(bag)
    assert source.problems == []
    assert [round(e.t, 6) for e in read] == [round(e.t, 6) for e in events]


def test_split_bag_without_metadata_keeps_file_order(tmp_path: Path) -> None:
    bag, events = _split_bag(tmp_path, "sqlite3")
    (bag / "metadata.yaml").unlink()
    source, read = read_all(bag)
    assert len(source.problems) == 1
    assert [round(e.t, 6) for e in read] == [round(e.t, 6) for e in events]
