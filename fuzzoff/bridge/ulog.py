"""PX4's side: the topics of its ULog that a bag's topics are compared with, and the bridge's
time sync.

Kept apart from ``fuzzoff.formats.ulog`` (the lint's reader): pyulog loads only the topics
asked for, whole. PX4's ``uxrce_dds_client`` says each time it synchronizes with an agent
("synchronized with time offset Nus", a logged message kept in a cut ULog): N is the agent's
clock minus PX4's, the offset the bridge subtracts from an incoming ``timestamp`` and adds to an
outgoing one (``min(value - offset, now)`` on receipt: a stamp in PX4's future becomes the
receive time; spec 2.1.1, ``Tools/msg/templates/ucdr/msg.h.em``). A log without that line (its
logging started after the client connected) may still hold the client's ``timesync_status``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fuzzoff.bridge import BridgeError

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
    if not syncs:
        syncs = _from_status(log.data_list)
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
            if source != SOURCE_PROTOCOL_DDS or offset == 0:
                continue
            if not syncs or abs(-int(offset) - syncs[-1][1]) > SESSION_JUMP_US:
                syncs.append((int(t), -int(offset)))
    return sorted(syncs)
