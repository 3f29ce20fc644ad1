"""Every registered format reads back what its own writer wrote, detected from content alone.

The registry (``fuzzoff.formats.registry``) is the one place a format is declared: a new
format's entry must agree with itself (detection, reader, writer, suffix) before lint or fuzz
can rely on it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzoff.events import (
    ControlMode,
    Event,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.formats import SourceError, detect_format, open_source
from fuzzoff.formats.format import Format
from fuzzoff.formats.registry import FORMATS, RECORDING_SUFFIXES
from fuzzoff.fuzz.recordings import read

UORB = [
    VehicleStatus(t=0.0, nav_state=2, armed=True),
    *(ControlMode(t=0.1 * i, position=True) for i in range(1, 11)),
    *(TrajectorySetpoint(t=0.1 * i + 0.01, position=(0.0, 0.0, -2.0)) for i in range(1, 11)),
]
MAVLINK = [
    VehicleStatus(t=0.0, nav_state=2, armed=True),
    *(SetPositionTargetLocal(t=0.1 * i, type_mask=0xDF8) for i in range(1, 11)),
]


def _stream(fmt: Format) -> list[Event]:
    return MAVLINK if set(fmt.transports) & {"mavlink", "mavros"} else UORB


@pytest.mark.parametrize("fmt", FORMATS, ids=lambda f: f.name)
def test_written_recording_is_detected_and_read(tmp_path: Path, fmt: Format) -> None:
    path = fmt.write(tmp_path / f"flight{fmt.written_suffix}", _stream(fmt), "1.15")
    name = detect_format(path)
    assert name in fmt.names
    with open_source(path) as source:
        assert source.format == name
        assert list(source.events())
    if fmt.written_suffix:
        assert fmt.written_suffix in RECORDING_SUFFIXES


def test_a_renamed_recording_is_still_detected_by_content(tmp_path: Path) -> None:
    by_name = {f.name: f for f in FORMATS}
    path = by_name["tlog"].write(tmp_path / "flight.tlog", MAVLINK)
    renamed = path.rename(tmp_path / "flight.bin")
    assert detect_format(renamed) == "tlog"
    assert read(renamed)


def test_a_folder_format_is_asked_through_the_registry(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A format whose recordings are folders is found by its ``is_folder`` and detected by its
    ``detect_folder``: the search and detection know no format by name."""
    import fuzzoff.formats as formats

    def fake_folder(path: Path) -> str:
        if not (path / f"{path.name}.idx").is_file():
            raise SourceError(path, "not a fake capture")
        return "fake-folder"

    folder = tmp_path / "capture"
    folder.mkdir()
    (folder / "capture.idx").write_text("")
    fake = Format(
        name="fake",
        reader="fuzzoff.formats.tlog.reader:TlogSource",
        writer="fuzzoff.formats.tlog.writer:write_tlog",
        clock="fuzzoff.formats.tlog.clock:start_s",
        detect_file=lambda path, head: None,
        names=("fake-folder",),
        suffixes=(".idx",),
        written_suffix="",
        is_folder=lambda path, suffixes: (path / f"{path.name}.idx").is_file(),
        detect_folder=fake_folder,
    )
    monkeypatch.setattr(formats, "FOLDER_FORMATS", (fake, *formats.FOLDER_FORMATS))
    assert formats.is_bag_folder(folder)
    assert detect_format(folder) == "fake-folder"
    assert formats.recordings_in([tmp_path]) == [folder]
    plain = tmp_path / "plain"
    plain.mkdir()
    with pytest.raises(SourceError, match="not a fake capture"):  # the first folder format's
        detect_format(plain)


@pytest.mark.parametrize("fmt", FORMATS, ids=lambda f: f.name)
def test_the_fleet_table_dates_a_recording_by_its_own_clock(tmp_path: Path, fmt: Format) -> None:
    """A ULog's clock counts from boot (no GPS fix here: no date); the others log Unix time."""
    from fuzzoff.fleet.wallclock import start_time
    from fuzzoff.formats.ros2msgs.messages import START_NS
    from fuzzoff.formats.rosbag1.writer import DEFAULT_START_NS
    from fuzzoff.formats.tlog.writer import DEFAULT_START_US

    path = fmt.write(tmp_path / f"flight{fmt.written_suffix}", _stream(fmt), "1.15")
    when = start_time(path, detect_format(path))
    expected = {
        "tlog": DEFAULT_START_US / 1e6,
        "mcap": START_NS / 1e9,
        "rosbag2": START_NS / 1e9,
        "rosbag1": DEFAULT_START_NS / 1e9,
    }.get(fmt.name)
    if expected is None:
        assert when is None
    else:
        assert when is not None
        assert when.timestamp() == pytest.approx(expected, abs=1e-3)
