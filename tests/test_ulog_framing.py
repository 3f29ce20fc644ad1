"""pyulog is handed only the data records a lint reads (``fuzzoff/formats/ulog/framing.py``, issue
31): the events, the recording's summary and every problem are those of pyulog reading every
record, on every corpus ULog; and on a damaged or unusual file the framing pass gives way to the
plain read, so the damage is said exactly as before."""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.formats.ulog.load import load
from fuzzoff.formats.ulog.reader import LOADED_TOPICS, UlogSource, _ReadRows
from fuzzoff.recording import PlotSamples, SourceError

ROOT = Path(__file__).resolve().parent.parent
ULOGS = sorted((ROOT / "corpora").rglob("*.ulg"))
BIGGEST = max((p for p in ULOGS if "sitl" in p.parts), key=lambda p: p.stat().st_size)


def _read(path: Path, whole: bool) -> tuple[Any, ...]:
    """What a lint takes from the file: the summary, the events and the problems."""
    source = UlogSource(path)
    source._whole = whole  # every row decoded by pyulog, as before the framing pass
    with source:
        info = source.probe()
        events = [repr(e) for e in source.events()]
    summary = (
        info.message_count,
        sorted(info.kinds),
        sorted(info.sampled_intervals.items()),
        info.notes,
        info.px4_version,
        info.vehicle_type,
    )
    problems = [p.line("f") for p in source.problems]
    return summary, events, problems, source.start_time_s, source.aside.end_t


@pytest.mark.parametrize("path", ULOGS, ids=lambda p: str(p.relative_to(ROOT)))
def test_framed_read_is_the_whole_read(path: Path) -> None:
    assert _read(path, whole=False) == _read(path, whole=True)


def test_a_real_log_is_framed() -> None:
    """The biggest real SITL ULog takes the framing pass, and pyulog decodes a part of it."""
    loaded = load(BIGGEST, LOADED_TOPICS, plan=_ReadRows())
    assert loaded.ulog.framed is not None
    assert loaded.rows_read  # the positions at least are thinned
    assert len(loaded.ulog.framed.data) < BIGGEST.stat().st_size - 1000


def _data_start(path: Path) -> int:
    """Where the data section begins: the first record past the definitions."""
    header = load(path, None, header_only=True).ulog.last_header("definitions")
    assert header is not None
    return int(header.start)


def _records(blob: bytes, start: int) -> list[int]:
    at, found = start, []
    while at + 3 <= len(blob):
        found.append(at)
        at += 3 + struct.unpack_from("<H", blob, at)[0]
    return found


def _mutations(blob: bytes, start: int) -> dict[str, bytes]:
    records = _records(blob, start)
    data = [r for r in records if blob[r + 2] == ord("D")]
    middle = data[len(data) // 2]
    sync = struct.pack("<HB", 8, ord("S")) + bytes([0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12])
    unknown_id = bytearray(blob)
    struct.pack_into("<H", unknown_id, middle + 3, 0xFFF0)
    short = bytearray(blob)
    struct.pack_into("<H", short, middle, 0)
    kind = bytearray(blob)
    kind[middle + 2] = ord("X")
    return {
        "cut inside a record": blob[: middle + 7],
        "cut inside a record header": blob[: middle + 2],
        "a sync record": blob[:middle] + sync + blob[middle:],
        "a message id no subscription names": bytes(unknown_id),
        "a data record whose size reads 0": bytes(short),
        "an unknown record type": bytes(kind),
        "a record past the end": blob[:middle] + struct.pack("<HB", 60000, ord("D")) + b"\0\0",
    }


DAMAGE = [
    "cut inside a record",
    "cut inside a record header",
    "a message id no subscription names",
    "a data record whose size reads 0",
    "an unknown record type",
    "a record past the end",
]


@pytest.mark.parametrize("mutation", DAMAGE)
def test_damage_is_said_as_the_plain_read_says_it(mutation: str, tmp_path: Path) -> None:
    blob = BIGGEST.read_bytes()
    path = tmp_path / "damaged.ulg"
    path.write_bytes(_mutations(blob, _data_start(BIGGEST))[mutation])
    try:
        framed = load(path, LOADED_TOPICS, plan=_ReadRows())
    except SourceError as exc:
        with pytest.raises(SourceError) as plain:
            load(path, LOADED_TOPICS)
        assert str(plain.value) == str(exc)
        return
    plain_load = load(path, LOADED_TOPICS)
    assert framed.ulog.framed is None  # pyulog read it all, as before
    assert not framed.rows_read
    assert [p.line("f") for p in framed.problems] == [p.line("f") for p in plain_load.problems]
    # pyulog steps over a record of a type it does not know with a plausible size, as before
    assert bool(framed.problems) == (mutation != "an unknown record type")
    assert _read(path, whole=False) == _read(path, whole=True)


def test_a_sync_record_is_read_by_pyulog(tmp_path: Path) -> None:
    """Not damage, but not what the framing pass hands on: pyulog reads such a file itself."""
    blob = BIGGEST.read_bytes()
    path = tmp_path / "sync.ulg"
    path.write_bytes(_mutations(blob, _data_start(BIGGEST))["a sync record"])
    loaded = load(path, LOADED_TOPICS, plan=_ReadRows())
    assert loaded.ulog.framed is None
    assert not loaded.problems
    assert _read(path, whole=False) == _read(path, whole=True)


def test_a_log_past_the_limit_is_read_by_pyulog(monkeypatch: pytest.MonkeyPatch) -> None:
    """The framing pass holds the data section in memory: past ``LIMIT`` pyulog reads alone."""
    monkeypatch.setattr("fuzzoff.formats.ulog.load.LIMIT", 1000)
    loaded = load(BIGGEST, LOADED_TOPICS, plan=_ReadRows())
    assert loaded.ulog.framed is None
    assert not loaded.rows_read


def test_plots_asked_for_after_open_get_every_position() -> None:
    """The HTML report's plots show the positions the events leave out: a source opened
    before the plots were asked for reads the file again, whole."""

    def positions(plot_first: bool) -> list[Any]:
        source = UlogSource(BIGGEST)
        if plot_first:
            source.aside.plot = PlotSamples()
        with source:
            source.probe()
            source.aside.plot = source.aside.plot or PlotSamples()
            events = [repr(e) for e in source.events()]
        return [events, repr(vars(source.aside.plot))]

    assert positions(plot_first=False) == positions(plot_first=True)


def test_a_log_with_little_to_leave_out_is_read_by_pyulog(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where too few records could be left out (``WORTH``), the pass stops after its walk."""
    monkeypatch.setattr("fuzzoff.formats.ulog.framing.WORTH", 1.01)
    loaded = load(BIGGEST, LOADED_TOPICS, plan=_ReadRows())
    assert loaded.ulog.framed is None
    assert _read(BIGGEST, whole=False) == _read(BIGGEST, whole=True)
