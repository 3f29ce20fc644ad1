"""Build the damaged-input corpus (run from the repo root; deterministic):

    .venv/bin/python corpora/damaged/build.py

Two recordings written by fuzzoff's writers through the real libraries, which the damage campaign
(tests/test_damaged_corpus.py) damages beside the other formats' corpus recordings:

* ``chunked.mcap``: the good MCAP flight of corpora/mcap (PX4 1.15, multicopter) in 2 kB zstd
  chunks (twenty chunks, each CRC-checked, and a summary with its CRC);
* ``chunked.bag``: the good MAVROS flight of corpora/rosbag1 in 4 kB chunks (twelve chunks).

Then damaged copies of them, each showing one kind of damage and what fuzzoff says about it. The
damage is applied to the bytes the writers produced, at places found with the libraries' own
readers. Nothing is lost in any of the OFB004 cases (the file is read around the damage), so
each expects the findings of its undamaged recording and one OFB004 (``info``: exit status as
the undamaged file's); ``stderr`` lists what the line must say.

Failures the damage campaign found (shrunk by Hypothesis), kept here:

* ``mcap_chunk_header_zeroed``: 44 zero bytes from the third byte of the second chunk's record
  (its length's high bytes, times, sizes, CRC, compression and data length): the chunk read as
  empty, without an error, and its 1.5 s of stream vanished in silence. Now OFB001 (the chunk's
  fields no longer fill its record), beside OFB004 (the summary's index of it disagrees). The
  readable part shows the hole: a 1.5 s keep-alive gap before the switch (OFB101 at 0.5 s; at
  the switch the newest keep-alive is 1.5 s old, so PX4 1.15 would reject it: OFB102 an error,
  OFB202 as the recording shows it accepted).
* ``mcap_one_chunk_flips``: corpora/stream/ofb104_good.mcap (one chunk) with three bits
  flipped: in the header, in the chunk's type byte (a chunk read as a SummaryOffset record) and
  in its compression's name. The summary's index disagreed, the file was read front to back,
  and the chunk, parsed as another record, gave no message and no error. Now OFB001: the record
  type that has no place in the data section, and nothing was read (no vehicle type: OFB003;
  no offboard in the part read: OFB005).
* ``mcap_chunk_type_flipped`` (OFB004, the case above with a sound summary): the second
  chunk's type byte reads 0x0e; its index and every other header field agree, so its messages
  are read through the summary, and the line says so.
* ``bag_index_zeroed``: 16 zero bytes in the index of ``chunked.bag`` (in a chunk-info
  record): read through that index, messages were missed with only OFB004 said. An index
  whose records do not read is not trusted: the bag is read in file order (OFB001, reindex
  advised) and every message is there (the findings of the intact flight).
* ``bag_chunk_info_zeroed``: 12 zero bytes a little further, in the same chunk-info record's
  message counts: its framing reads, but rosbags skipped the chunk. The chunk infos are
  checked against the chunks' own index records: the same as above.
* ``bag_chunk_count_flipped``: one bit of the bag header's ``chunk_count`` (9 read as 8): rosbags
  read one chunk info less and that chunk's messages were lost, while the chunk info it left
  out was said as "bytes after the bag's index" (OFB004, complete). An index record after the
  counted ones means the counts are damaged: read in file order (OFB001, reindex advised), every
  message there. Found by a 2,000-copy sweep of the damage campaign.
* ``mcap_bag_channel_zeroed``: 23 zero bytes over a Channel record in the summary of
  corpora/rosbag2/stream_lost_mcap (no summary CRC from rosbag2's writer): rosbags dropped
  that channel's 79 messages, and fuzzoff took the summary's statistics for the data's count.
  A summary without a channel its chunk indexes name is not trusted: read front to back, every
  message (the findings of the intact bag and one OFB004).
* ``metadata_start_digit``: corpora/rosbag2/two_vehicles with one bit flipped in a digit of
  metadata.yaml's starting time: every time moved by that much in silence. Now OFB004, and the
  data files' own first time is used (the findings of the intact bag).

Intact recordings under names that are not their format's (issue 26 item 3): a recording is
read as what its content is, so each expects its undamaged findings and nothing else.

* ``renamed.MCAP``, ``renamed.mcap.active``, ``renamed_mcap`` (``chunked.mcap``): read as a
  damaged SQLite database (OFB001, exit 2, the flight's findings gone).
* ``renamed.DB3`` (corpora/rosbag2/good_flight_sqlite3's database): "salvaged" row by row
  (OFB001), the PX4 release assumed instead of read from its definitions.
"""

from __future__ import annotations

import importlib.util
import io
import json
import shutil
import struct
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "corpora" / "mcap"))

from flights import Flight  # noqa: E402  (corpora/mcap/flights.py)
from mcap.reader import SeekingReader  # noqa: E402
from rosbags.rosbag1.reader import Header, RecordType  # noqa: E402

from fuzzoff.formats.mcap.writer import write_mcap  # noqa: E402
from fuzzoff.formats.rosbag1.writer import write_rosbag1  # noqa: E402

_spec = importlib.util.spec_from_file_location("rosbag1_build", ROOT / "corpora/rosbag1/build.py")
assert _spec is not None and _spec.loader is not None
rosbag1_build = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rosbag1_build)


def intact(expected_json: str) -> dict[str, Any]:
    """The planted expectations of an undamaged corpus recording (the same flight)."""
    spec: dict[str, Any] = json.loads((ROOT / "corpora" / expected_json).read_text())
    return spec


MCAP_FINDINGS = intact("mcap/good_flight.expected.json")["findings"]
MCAP_PROFILE = {"px4": "1.15", "vehicle": "mc", "detected": True}
BAG_FINDINGS = intact("rosbag1/offboard_good.expected.json")["findings"]
MALFORMED = {"code": "OFB004", "severity": "info", "time_s": None}


def expected(name: str, recording: str, findings: list[dict[str, Any]], **spec: Any) -> None:
    out: dict[str, Any] = {
        "recording": recording,
        "args": [],
        "exit_status": 0,
        "complete": True,
        **spec,
        "findings": findings,
    }
    (HERE / f"{name}.expected.json").write_text(json.dumps(out, indent=2) + "\n")


def patched(data: bytes, at: int, new: bytes) -> bytes:
    return data[:at] + new + data[at + len(new) :]


def mcap_cases(data: bytes) -> dict[str, tuple[bytes, str]]:
    """name -> (damaged bytes, what the OFB004 line says)."""
    summary = SeekingReader(io.BytesIO(data)).get_summary()
    assert summary is not None
    footer = len(data) - 8 - 29  # the Footer record: opcode, length, three fields; then magic
    fourth = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[3]
    no_crc = patched(data, footer + 1 + 8 + 16, b"\0\0\0\0")  # summary_crc 0: none given
    # The chunk index copies its chunk's times: one of them wrong made rosbags skip the chunk.
    index_at = no_crc.index(struct.pack("<QQ", fourth.message_start_time, fourth.message_end_time))
    message_index = min(fourth.message_index_offsets.values())
    second = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[1]
    return {
        "mcap_chunk_type_flipped": (
            patched(data, second.chunk_start_offset, b"\x0e"),
            "a record of type 0x0e in the data section; its messages were read through",
        ),
        "mcap_trailing_garbage": (
            data + b"\n-- appended by a copy tool --\n" * 8,
            "bytes after the end of the MCAP file",
        ),
        "mcap_summary_start_past_end": (
            patched(data, footer + 9, struct.pack("<Q", 10_000_000)),
            "the footer's summary offset (10000000) is past the end",
        ),
        "mcap_chunk_index_times": (
            patched(no_crc, index_at + 8, struct.pack("<Q", 0)),
            f"the summary's index of the chunk at byte {fourth.chunk_start_offset} disagrees",
        ),
        "mcap_record_length_huge": (
            patched(data, message_index + 1, struct.pack("<Q", 2**64 - 1)),
            "a record claims 18446744073709551615 bytes",
        ),
    }


def chunk_header_zeroed(data: bytes) -> bytes:
    summary = SeekingReader(io.BytesIO(data)).get_summary()
    assert summary is not None
    second = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[1]
    at = second.chunk_start_offset + 3
    return patched(data, at, bytes(44))


def one_chunk_flips() -> bytes:
    """The campaign's case: ('flip', 29, 41, 2) on ofb104_good.mcap, three bits 41 bytes apart."""
    data = bytearray((ROOT / "corpora" / "stream" / "ofb104_good.mcap").read_bytes())
    assert data[70] == 0x06  # the chunk's type byte
    for k, at in enumerate((29, 70, 111)):
        data[at] ^= 1 << (2 + k)
    return bytes(data)


def metadata_start_digit(folder: Path) -> None:
    """The campaign's case: byte 459 of two_vehicles' metadata.yaml, its lowest bit flipped."""
    meta = folder / "metadata.yaml"
    text = meta.read_bytes()
    assert text[447:466] == b"1700000000000000000"  # its starting time: byte 459 in there
    meta.write_bytes(patched(text, 459, bytes([text[459] ^ 1])))


def bag_cases(data: bytes) -> dict[str, tuple[bytes, str]]:
    bio = io.BytesIO(data)
    bio.readline()
    Header.read(bio, RecordType.BAGHEADER)
    data_len_at = bio.tell()  # the bag header record's data length, after its header
    index_pos = Header.read(io.BytesIO(data[13:]), RecordType.BAGHEADER).get_uint64("index_pos")
    assert index_pos < 50078 < len(data)  # the campaign's place: a chunk-info record
    chunk_count_at = data.index(b"chunk_count=", 13) + len(b"chunk_count=")  # low byte first
    return {
        "bag_index_zeroed": (
            patched(data, 50078, bytes(16)),
            "index damaged at byte",
        ),
        "bag_chunk_info_zeroed": (patched(data, 50082, bytes(12)), "index damaged at byte"),
        "bag_chunk_count_flipped": (
            patched(data, chunk_count_at, bytes([data[chunk_count_at] ^ 1])),
            "index damaged at byte",
        ),
        "bag_header_data_len": (
            patched(data, data_len_at, b"\xff\xff\xff\xff"),
            "the bag header's data length runs past the end",
        ),
        "bag_trailing_garbage": (data + b"\0" * 300, "300 bytes after the bag's index"),
    }


def main() -> None:
    mcap = write_mcap(HERE / "chunked.mcap", Flight().events(), release="1.15", chunk_size=2048)
    clean = ["OFB001", "OFB004"]
    expected("chunked", "chunked.mcap", MCAP_FINDINGS, profile=MCAP_PROFILE, clean=clean)
    modes = [(0.0, "POSCTL"), (3.0, "OFFBOARD"), (11.0, "AUTO.LAND")]
    good = rosbag1_build.flight(modes, rosbag1_build.setpoints(1.0, 12.0), 12.0)
    bag = write_rosbag1(HERE / "chunked.bag", good, chunk_threshold=4096)
    expected("chunked_bag", "chunked.bag", BAG_FINDINGS, clean=clean)

    for name, (damaged, says) in mcap_cases(mcap.read_bytes()).items():
        (HERE / f"{name}.mcap").write_bytes(damaged)
        findings = [*MCAP_FINDINGS, MALFORMED]
        expected(name, f"{name}.mcap", findings, profile=MCAP_PROFILE, stderr=[says])
    (HERE / "mcap_chunk_header_zeroed.mcap").write_bytes(chunk_header_zeroed(mcap.read_bytes()))
    hole = [
        {"code": "OFB001", "severity": "error", "time_s": None},
        {"code": "OFB002", "severity": "info", "time_s": None},
        MALFORMED,
        {"code": "OFB101", "severity": "error", "time_s": 0.5},
        {"code": "OFB102", "severity": "error", "time_s": 2.0},
        {"code": "OFB202", "severity": "warning", "time_s": 2.01},
        {"code": "OFB701", "severity": "info", "time_s": 2.02},
    ]
    says = ["chunk header damaged", "the summary's index of the chunk at byte"]
    expected(
        "mcap_chunk_header_zeroed",
        "mcap_chunk_header_zeroed.mcap",
        hole,
        exit_status=2,
        complete=False,
        profile=MCAP_PROFILE,
        stderr=says,
    )
    (HERE / "mcap_one_chunk_flips.mcap").write_bytes(one_chunk_flips())
    nothing = [
        {"code": "OFB001", "severity": "error", "time_s": None},
        {"code": "OFB003", "severity": "info", "time_s": None},
        MALFORMED,
        # nothing read, so no offboard in the part read
        {"code": "OFB005", "severity": "info", "time_s": None},
    ]
    says = ["a record of type 0x0e in the data section (a damaged record type)"]
    profile = {"px4": "1.15", "vehicle": "mc", "detected": False}
    spec = {"exit_status": 2, "complete": False, "profile": profile, "stderr": says}
    expected("mcap_one_chunk_flips", "mcap_one_chunk_flips.mcap", nothing, **spec)
    folder = HERE / "mcap_bag_channel_zeroed"
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(ROOT / "corpora" / "rosbag2" / "stream_lost_mcap", folder)
    data_file = folder / "stream_lost_mcap.mcap"
    data_file.write_bytes(patched(data_file.read_bytes(), 34270, bytes(23)))
    lost_spec = intact("rosbag2/stream_lost_mcap.expected.json")
    expected(
        "mcap_bag_channel_zeroed",
        "mcap_bag_channel_zeroed",
        [*lost_spec["findings"], MALFORMED],
        exit_status=lost_spec["exit_status"],
        profile=lost_spec["profile"],
        stderr=["the summary lacks the channel 5 its chunk indexes name"],
    )
    folder = HERE / "metadata_start_digit"
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(ROOT / "corpora" / "rosbag2" / "two_vehicles", folder)
    metadata_start_digit(folder)
    bag_spec = intact("rosbag2/two_vehicles.expected.json")
    expected(
        "metadata_start_digit",
        "metadata_start_digit",
        [*bag_spec["findings"], MALFORMED],
        exit_status=bag_spec["exit_status"],
        profile=bag_spec["profile"],
        stderr=["metadata.yaml's starting time is", "the data files' times were used"],
    )
    for name in ("renamed.MCAP", "renamed.mcap.active", "renamed_mcap"):
        shutil.copyfile(mcap, HERE / name)
        case = name.replace(".", "_")
        expected(case, name, MCAP_FINDINGS, profile=MCAP_PROFILE, clean=clean)
    database = ROOT / "corpora" / "rosbag2" / "good_flight_sqlite3" / "good_flight_sqlite3.db3"
    shutil.copyfile(database, HERE / "renamed.DB3")
    sqlite_spec = intact("rosbag2/good_flight_sqlite3.expected.json")
    expected(
        "renamed_DB3",
        "renamed.DB3",
        sqlite_spec["findings"],
        exit_status=sqlite_spec["exit_status"],
        profile=sqlite_spec["profile"],
        clean=clean,
    )
    for name, (damaged, says) in bag_cases(bag.read_bytes()).items():
        (HERE / f"{name}.bag").write_bytes(damaged)
        if name in ("bag_index_zeroed", "bag_chunk_info_zeroed", "bag_chunk_count_flipped"):
            unread = {"code": "OFB001", "severity": "error", "time_s": None}
            spec = {"exit_status": 2, "complete": False, "stderr": [says]}
            expected(name, f"{name}.bag", [unread, *BAG_FINDINGS], **spec)
            continue
        expected(name, f"{name}.bag", [*BAG_FINDINGS, MALFORMED], stderr=[says])


if __name__ == "__main__":
    main()
