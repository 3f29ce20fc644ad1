"""Time order for MCAP read in file order (the streaming salvage path): ``ChunkOrder``."""

from __future__ import annotations

from fuzzoff.events import ControlMode
from fuzzoff.formats.ros2.order import MAX_PENDING, ChunkOrder


def _event(t: float) -> ControlMode:
    return ControlMode(t=t)


def _drain(order: ChunkOrder, chunks: list[list[float]]) -> list[float]:
    out: list[float] = []
    for chunk in chunks:
        out += [e.t for e in order.boundary(round(min(chunk) * 1e9))]
        for t in chunk:
            out += [e.t for e in order.add(round(t * 1e9), _event(t))]
    out += [e.t for e in order.flush()]
    return out


def test_overlapping_chunks_come_out_in_time_order() -> None:
    order = ChunkOrder()
    chunks = [[0.0, 0.2, 0.1, 0.4], [0.3, 0.5, 0.45], [0.6, 0.55, 0.7]]
    assert _drain(order, chunks) == sorted(t for chunk in chunks for t in chunk)
    assert order.late == 0


def test_disorder_beyond_a_chunk_is_counted_not_hidden() -> None:
    order = ChunkOrder()
    result = _drain(order, [[1.0, 2.0], [3.0, 4.0], [0.5]])
    assert sorted(result) == [0.5, 1.0, 2.0, 3.0, 4.0]
    assert order.late == 1


def test_without_chunks_memory_stays_bounded() -> None:
    order = ChunkOrder()
    released = 0
    for k in range(3 * MAX_PENDING):
        released += sum(1 for _ in order.add(k, _event(k / 1e9)))
        assert k + 1 - released <= MAX_PENDING + 1
    assert released + sum(1 for _ in order.flush()) == 3 * MAX_PENDING
