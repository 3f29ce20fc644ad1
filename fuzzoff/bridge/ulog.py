"""PX4's side: the topics of its ULog that a bag's topics are compared with, and the bridge's
time sync.

Kept apart from ``fuzzoff.formats.ulog`` (the lint's reader): pyulog loads only the topics
asked for, whole. PX4's ``uxrce_dds_client`` says each time it synchronizes with an agent
("synchronized with time offset Nus", a logged message kept in a cut ULog): N is the agent's
clock minus PX4's, the offset the bridge subtracts from an incoming ``timestamp`` and adds to an
outgoing one (``min(value - offset, now)`` on receipt: a stamp in PX4's future becomes the
receive time; spec 2.1.1, ``Tools/msg/templates/ucdr/msg.h.em``). A log without that line (its
logging started after the client connected) may still hold the client's ``timesync_status``,
which also shows where the client jumped to a new offset within one session (its filter
reset: a simulated PX4 off the host's pace, no new "synchronized" line).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from fuzzoff.bridge import BridgeError
from fuzzoff.lean_dataclass import dataclass

SYNCED = re.compile(r"synchronized with time offset (-?\d+)\s*us")
SOURCE_PROTOCOL_DDS = 2
"""``timesync_status.source_protocol`` of the bridge's client (seen on the 1.18 head)."""
SESSION_JUMP_US = 20_000
"""``timesync_status``: an offset this far from the last one starts a new session."""


@dataclass(frozen=True, slots=True)
class ULogTopic:
    name: str
    timestamps: np.ndarray
    """µs, PX4's clock (sorted)."""
    data: dict[str, np.ndarray]


@dataclass(frozen=True, slots=True)
class Px4Log:
    path: str
    start_us: int
    last_us: int
    syncs: list[tuple[int, int]]
    """(PX4 time, offset µs) of each time sync with an agent, in order."""
    topics: dict[str, ULogTopic]
    synct: int | None = None
    """PX4's ``UXRCE_DDS_SYNCT`` (0: the bridge ran without time sync), None when unlogged."""


def read_ulog(path: Path, names: set[str]) -> Px4Log:
    """``names`` of ``path`` (those logged); BridgeError when it cannot be read."""
    from pyulog import ULog

    try:
        log = ULog(str(path), message_name_filter_list=sorted(names | {"timesync_status"}))
    except Exception as exc:  # pyulog raises what its parsing meets
        raise BridgeError(f"{path}: cannot read the ULog ({exc})") from None
    syncs = []
    for logged in log.logged_messages:
        match = SYNCED.search(logged.message)
        if match is not None:
            syncs.append((int(logged.timestamp), int(match.group(1))))
    syncs = _with_jumps(syncs, log.data_list)
    topics: dict[str, ULogTopic] = {}
    for dataset in log.data_list:
        if dataset.multi_id != 0 or dataset.name in topics:
            continue
        data: dict[str, Any] = dataset.data
        order = np.argsort(data["timestamp"], kind="stable")
        sorted_data = {k: v[order] for k, v in data.items()}
        topics[dataset.name] = ULogTopic(
            dataset.name, sorted_data["timestamp"].astype(np.int64), sorted_data
        )
    synct = log.initial_parameters.get("UXRCE_DDS_SYNCT")
    return Px4Log(
        str(path),
        int(log.start_timestamp),
        int(log.last_timestamp),
        syncs,
        topics,
        None if synct is None else int(synct),
    )


def _from_status(datasets: list[Any]) -> list[tuple[int, int]]:
    """The sessions' offsets from the bridge's ``timesync_status`` (logged at 1 Hz), for a log
    without the time sync line (one started after the client connected): its
    ``estimated_offset`` is PX4's clock less the agent's, the line's offset negated."""
    syncs: list[tuple[int, int]] = []
    for t, offset in _status_offsets(datasets):
        if not syncs or abs(offset - syncs[-1][1]) > SESSION_JUMP_US:
            syncs.append((t, offset))
    return syncs


def _with_jumps(synced: list[tuple[int, int]], datasets: list[Any]) -> list[tuple[int, int]]:
    """The logged time syncs (``synced``) with the offset jumps the bridge's
    ``timesync_status`` shows within a session: the client's filter, converged on an offset
    while a simulated PX4 drifted off the host's pace, resets to the observed one (0.23 s at
    once on main, between two 1 Hz samples, with no "synchronized" line), and PX4's outputs
    from then on carry the new offset. A jump is two consecutive samples more than
    ``SESSION_JUMP_US`` apart (the estimate that follows a drifting PX4 moves a few ms a
    second) to an offset no logged sync has. Without a logged sync the status's sessions are
    the syncs (``_from_status``)."""
    if not synced:
        return _from_status(datasets)
    merged = sorted(synced)
    previous: int | None = None
    for t, offset in _status_offsets(datasets):
        jumped = previous is not None and abs(offset - previous) > SESSION_JUMP_US
        previous = offset
        if not jumped or t < merged[0][0]:
            continue
        current = [o for s, o in merged if s <= t][-1]
        if abs(offset - current) > SESSION_JUMP_US:
            merged.append((t, offset))
            merged.sort()
    return merged


def _status_offsets(datasets: list[Any]) -> list[tuple[int, int]]:
    """(PX4 time, offset µs as the "synchronized" line gives it) of each of the bridge's
    ``timesync_status`` samples: its ``estimated_offset`` is PX4's clock less the agent's."""
    found: list[tuple[int, int]] = []
    for dataset in datasets:
        data = dataset.data
        if dataset.name != "timesync_status" or "estimated_offset" not in data:
            continue
        for t, offset, source in zip(
            data["timestamp"].tolist(),
            data["estimated_offset"].tolist(),
            data.get("source_protocol", np.full(len(data["timestamp"]), -1)).tolist(),
            strict=True,
        ):
            if source == SOURCE_PROTOCOL_DDS and offset != 0:
                found.append((int(t), -int(offset)))
    return sorted(found)
