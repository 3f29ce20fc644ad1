"""The readers' fast paths give what their general paths give (speed work must not change events).

* ULog: the merge worked out in numpy (``_merged_order``) against ``heapq.merge`` of the keyed
  streams, on every ULog in the corpora;
* ROS 2: ``TopicDecoder.event`` (one-step decode of the usual payload) against ``_checked`` (the
  general path) on good, padded, big-endian, cut and foreign payloads;
* ``bundled_layout`` (parse only) against the layout a rosbags type store holds.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from fuzzoff.events import Event, event_to_dict
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.ros2msgs.convert import BUILDERS
from fuzzoff.formats.ros2msgs.decode import Ros2Decoding, TopicDecoder, bundled, bundled_layout
from fuzzoff.formats.ulog import reader as ulog_module
from fuzzoff.formats.ulog.reader import UlogSource

ROOT = Path(__file__).resolve().parent.parent
ULOGS = sorted((ROOT / "corpora").rglob("*.ulg"))


def _read(path: Path) -> list[str]:
    """Every event as text (NaN compares equal there)."""
    source = UlogSource(path)
    with source:
        source.probe()
        return [repr(event_to_dict(e)) for e in source.events()]


def test_there_are_ulogs_to_compare() -> None:
    assert len(ULOGS) >= 5


@pytest.mark.parametrize("path", ULOGS, ids=lambda p: p.name)
def test_ulog_numpy_merge_is_heapq_merge(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fast = _read(path)
    monkeypatch.setattr(ulog_module, "_merged_order", lambda streams: None)
    assert _read(path) == fast


def test_ulog_merge_orders_ties_by_rank_then_index() -> None:
    """Equal times: lower rank first, then row order; the preamble first; records last."""
    np = pytest.importorskip("numpy")

    def stream(keys: list[int], rank: int, index: list[int]) -> Any:
        names = iter([f"{rank}:{i}" for i in index])
        return ulog_module._Stream(np.array(keys, dtype=np.uint64), rank, np.array(index), names)

    def keyed(items: list[tuple[int, int, int, str]]) -> Any:
        return ulog_module._Stream.of(iter(items))  # type: ignore[arg-type]

    preamble = keyed([(-1, 0, 0, "info"), (-1, 1, 0, "param")])
    topics = [stream([5, 5, 7], 2600, [1, 0, 2]), stream([5, 6, 7], 2570, [0, 1, 2])]
    records = keyed([(5, 1 << 20, 0, "rec")])
    streams = [preamble, *topics, records]
    order = ulog_module._merged_order(streams)
    assert order is not None
    iters: list[Iterator[Any]] = [iter(s.events) for s in streams]
    got = [next(iters[s]) for s in order.tolist()]
    again = [preamble, *topics, records]
    for s, fresh in zip(again[1:3], [[1, 0, 2], [0, 1, 2]], strict=True):
        s.events = iter([f"{s.rank}:{i}" for i in fresh])
    preamble.events = iter(["info", "param"])
    records.events = iter(["rec"])
    import heapq

    want = [e for *_, e in heapq.merge(*(s.keyed() for s in again))]
    assert got == want
    assert got[:2] == ["info", "param"]
    assert got[2:6] == ["2570:0", "2600:1", "2600:0", "rec"]


def _decoder(message: str, release: str) -> TopicDecoder:
    decoding = Ros2Decoding()
    decoder = decoding.connection(f"/fmu/in/{message.lower()}", px4_msgs.type_name(message), None)
    assert isinstance(decoder, TopicDecoder)
    definition = bundled(message, release)
    assert definition is not None
    decoder.use(definition)
    return decoder


def _payloads(decoder: TopicDecoder) -> list[bytes]:
    assert decoder.definition is not None
    definition = decoder.definition
    message = definition.cls(**{name: _zero(kind) for name, kind in definition.layout})
    good = bytes(definition.store.serialize_cdr(message, definition.typename))
    big = bytes(definition.store.serialize_cdr(message, definition.typename, little_endian=False))
    return [
        good,
        good + b"\x00" * (-len(good) % 4),  # zero padding: accepted
        good + b"\x01",  # a stray byte: rejected
        good + b"\x00" * 8,  # a longer payload (newer release): rejected
        big,
        good[: len(good) // 2],
        good[:3],
        b"",
        b"\x01\x01\x00\x00" + good[4:],  # bad encapsulation
    ]


def _zero(kind: Any) -> Any:
    import numpy as np

    node, detail = kind
    if node.name == "ARRAY":
        (_, (base, _)), size = detail
        return np.zeros(size, dtype=np.float32 if base.startswith("float") else np.uint8)
    base = detail[0]
    if base == "bool":
        return False
    if base.startswith("float"):
        return 0.25
    return 3


@pytest.mark.parametrize("message", ["TrajectorySetpoint", "OffboardControlMode"])
def test_ros2_one_step_decode_is_the_checked_decode(message: str) -> None:
    fast, slow = _decoder(message, "1.15"), _decoder(message, "1.15")
    for raw in _payloads(fast):
        got = fast.event(raw, 1.5)
        slow.index += 1
        want = slow._checked(raw, 1.5, slow.index - 1)
        assert (got is None) == (want is None), raw
        if isinstance(got, Event) and isinstance(want, Event):
            assert repr(event_to_dict(got)) == repr(event_to_dict(want))
    assert (fast.index, fast.failed, fast.first_failure) == (
        slow.index,
        slow.failed,
        slow.first_failure,
    )
    assert fast.failed >= 4


def test_bundled_layout_is_the_type_store_layout() -> None:
    for message in BUILDERS:
        for release in px4_msgs.releases_with(message):
            typename = px4_msgs.type_name(message)
            text = px4_msgs.definition(release, message)
            assert text is not None
            store = px4_msgs.typestore_for(typename, text)
            assert bundled_layout(message, release) == tuple(store.fielddefs[typename][1])


def test_rosbag1_decoder_is_the_library_call() -> None:
    """``_decoder`` gives rosbags' message, or raises rosbags' own error, for any payload."""
    from fuzzoff.formats.rosbag1.chunkwise import ChunkwiseReader
    from fuzzoff.formats.rosbag1.reader import Rosbag1Source, _decoder

    bag = ROOT / "corpora" / "rosbag1" / "offboard_good.bag"
    source = Rosbag1Source(bag)
    source.open()
    store = source._typestore
    reader = ChunkwiseReader(bag)
    reader.open()
    try:
        seen = set()
        for conn, _, raw in reader.messages(connections=source._wanted):
            if conn.msgtype in seen:
                continue
            seen.add(conn.msgtype)
            decode = _decoder(store, conn.msgtype)
            for payload in (raw, raw + b"\x00", raw[:-1], raw[:5], b""):
                try:
                    want: Any = repr(store.deserialize_ros1(payload, conn.msgtype))
                except Exception as exc:
                    want = (type(exc), str(exc))
                try:
                    got: Any = repr(decode(payload))
                except Exception as exc:
                    got = (type(exc), str(exc))
                assert got == want
        assert len(seen) >= 2
    finally:
        reader.close()
        source.close()
    unknown = _decoder(store, "nobody_msgs/msg/Nothing")
    with pytest.raises(Exception) as raised:
        unknown(b"")
    with pytest.raises(type(raised.value)):
        store.deserialize_ros1(b"", "nobody_msgs/msg/Nothing")
