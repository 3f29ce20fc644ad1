"""PX4 ULog reader: pyulog loads the topics that matter, events come out merged by timestamp.

pyulog cannot stream (formats.md 9.1): it reads the whole file once, keeping only the topics of
``LOADED_TOPICS`` (``message_name_filter_list``), as numpy arrays. Events are then made lazily,
per topic in chunks, and merged by timestamp with ``heapq.merge``; nothing builds the whole
event list. ``t`` is seconds since the ULog header's start time, ``sender_time_us`` the topic's
``timestamp``; every event's origin is "vehicle" (PX4's own copy, docs/ulog.md).

The logger subsamples topics (formats.md 8.1, rules.md "Keep-alive"), so ``probe`` reports the
logging interval of each offboard topic in ``RecordingInfo.sampled_intervals``.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterator
from itertools import chain, repeat
from pathlib import Path
from typing import Any

import numpy as np

from fuzzoff import events as ev
from fuzzoff import releases
from fuzzoff.formats.ulog.load import Loaded, load, quoted
from fuzzoff.formats.ulog.thinning import THINNED_KINDS, Windows, windows_for
from fuzzoff.formats.ulog.topics import (
    EXTRA_FIELDS,
    EXTRA_TOPICS,
    GPS_TOPICS,
    TOPICS,
    Chunk,
    Context,
    failsafe_flags,
    renamed_fields,
)
from fuzzoff.formats.uorb import MAIN_STATE_TO_NAV
from fuzzoff.profiles import MAV_TYPE_VEHICLE, PX4_VEHICLE_TYPE, ProfileError, px4_profile_for
from fuzzoff.recording import (
    POSITION_PERIOD_S,
    RecordingInfo,
    Source,
    SourceError,
    SourceProblem,
)

LOADED_TOPICS: tuple[str, ...] = (*TOPICS, *EXTRA_TOPICS, *GPS_TOPICS)
"""The topics read; the GPS ones only date the log (``start_time_s``), none of their rows is
an event or counted as a message."""
CHUNK_ROWS = 4096
"""Rows turned into Python values at a time (bounds memory on long logs)."""

CA_AIRFRAME_VEHICLE: dict[int, str] = {
    0: "mc",
    1: "fw",
    2: "vtol",
    3: "vtol",
    4: "vtol",
    5: "rover-ackermann",
    6: "rover-differential",
    8: "mc",
    10: "mc",
    11: "mc",
    12: "mc",
    13: "rover-mecanum",
}
"""``CA_AIRFRAME`` (v1.14+ control allocation) -> vehicle type; the only parameter that names
the rover drive in every release that has it."""

ROVER_PARAM_PREFIX: dict[str, str] = {
    "RA_": "rover-ackermann",
    "RD_": "rover-differential",
    "RM_": "rover-mecanum",
}
"""v1.16+ rover modules' parameter prefixes; a firmware that builds in only one of them names
the drive by that alone (SITL builds all three, so several prefixes tell nothing)."""

_SORTED_FIRST = -1
"""Merge key for what a ULog says before any message (initial parameters, identity)."""
_RECORD_RANK = 1 << 20
"""Records without a topic sort after the topics at the same microsecond (pyulog dates a
parameter change at the data message just before it)."""


def decode_release(word: int) -> str | None:
    """``ver_sw_release`` ``0xAABBCCTT`` -> ``"1.15.4"`` (``-rc``, ``-beta``, ``-alpha``,
    ``-dev`` for TT < 255); None for 0 (a build without a release tag)."""
    if not word:
        return None
    major, minor, patch, kind = (
        (word >> 24) & 0xFF,
        (word >> 16) & 0xFF,
        (word >> 8) & 0xFF,
        word & 0xFF,
    )
    base = f"{major}.{minor}.{patch}"
    if kind == 255:
        return base
    suffix = "rc" if kind >= 192 else "beta" if kind >= 128 else "alpha" if kind >= 64 else "dev"
    return f"{base}-{suffix}"


def vehicle_from_params(params: dict[str, Any]) -> tuple[str | None, str]:
    """The vehicle type the parameters name, and which parameter said so."""
    airframe = params.get("CA_AIRFRAME")
    if airframe is not None and int(airframe) in CA_AIRFRAME_VEHICLE:
        return CA_AIRFRAME_VEHICLE[int(airframe)], f"CA_AIRFRAME={int(airframe)}"
    families = {
        vehicle
        for prefix, vehicle in ROVER_PARAM_PREFIX.items()
        if any(name.startswith(prefix) for name in params)
    }
    mav_type = params.get("MAV_TYPE")
    rover_mav = mav_type is not None and MAV_TYPE_VEHICLE.get(int(mav_type), "").startswith("rover")
    if len(families) == 1 and (mav_type is None or rover_mav):
        (vehicle,) = families
        return vehicle, "only the " + vehicle.split("-")[1] + " rover parameters exist"
    if mav_type is not None and int(mav_type) in MAV_TYPE_VEHICLE:
        return MAV_TYPE_VEHICLE[int(mav_type)], f"MAV_TYPE={int(mav_type)}"
    return None, ""


class UlogSource(Source):
    """A PX4 ULog (.ulg), read with pyulog 1.3.

    ``events`` skips the rows of PX4's own high-rate setpoint topics that cannot be the
    external controller's (``thinning``); ``every_row=True`` reads every row."""

    format = "ulog"
    every_row = False
    """Read every row of the thinned topics (for a tool that wants PX4's own setpoints too)."""

    def __init__(self, path: Path, *, every_row: bool | None = None) -> None:
        super().__init__(path)
        if every_row is not None:
            self.every_row = every_row
        self._loaded: Loaded | None = None
        self._failed: SourceError | None = None
        self._info: RecordingInfo | None = None
        self._yielded = 0
        self._total = 0
        self._whole = False
        """Every row decoded, whatever ``every_row`` says (see ``events``)."""

    # -- loading ---------------------------------------------------------------------------

    def open(self) -> None:
        """Read the file: one that is not a ULog fails here, at once. The filtered data load
        (kept for ``probe`` and ``events``) reads the definition section on its way, which
        pyulog parsed a second time when ``open`` read it alone (issue 31); where that load
        fails, the definition section alone decides, as before, whether the file opens, and
        ``probe`` raises the load's error."""
        try:
            self._load()
        except SourceError:
            self.probe_header()

    def probe_header(self) -> RecordingInfo:
        """Version, parameters and vehicle type from the definition section only (instant)."""
        header = load(self.path, None, header_only=True)
        info = RecordingInfo(str(self.path), self.format, vehicles=[""])
        self._identity(header.ulog, info, None)
        return info

    def _load(self) -> Loaded:
        if self._failed is not None:
            raise self._failed
        if self._loaded is None:
            # The rows a lint reads, told to the load (``framing``): not for a tool that wants
            # every row, nor where the HTML report plots the positions the events leave out.
            thin = not (self.every_row or self._whole) and self.aside.plot is None
            try:
                loaded = load(self.path, LOADED_TOPICS, plan=_ReadRows() if thin else None)
                renamed = _drop_renamed_fields(loaded.ulog)
                if renamed and loaded.rows_read:  # the plan read the topics the lint drops
                    loaded = load(self.path, LOADED_TOPICS)
                    renamed = _drop_renamed_fields(loaded.ulog)
            except SourceError as exc:
                self._failed = exc
                raise
            self._loaded = loaded
            self.problems.extend(loaded.problems)
            self.problems.extend(renamed)
            if loaded.library_output:
                self.stats["pyulog_messages"] = loaded.library_output[:20]
        return self._loaded

    def _datasets(self) -> list[Any]:
        return [
            d
            for d in self._load().ulog.data_list
            if "timestamp" in d.data and len(d.data["timestamp"])
        ]

    # -- probe -----------------------------------------------------------------------------

    def probe(self) -> RecordingInfo:
        """The filtered data load (``open`` has read the header): the kinds present and the
        logging intervals need the data, as a ULog has no index. Kept for ``events``."""
        if self._info is not None:
            return self._info
        ulog = self._load().ulog
        info = RecordingInfo(str(self.path), self.format, vehicles=[""])
        datasets = self._datasets()
        status = next((d for d in datasets if d.name == "vehicle_status"), None)
        self._identity(ulog, info, status)
        info.message_count = sum(
            len(d.data["timestamp"]) for d in datasets if d.name not in GPS_TOPICS
        )
        for d in datasets:
            spec = TOPICS.get(d.name)
            if spec is None:
                continue
            kind = _kind(d)
            info.kinds.add(kind)
            if spec.setpoint:
                interval = _interval(d.data["timestamp"], spec.default_interval_s)
                if interval is not None:
                    current = info.sampled_intervals.get(kind)
                    info.sampled_intervals[kind] = min(interval, current or interval)
        if "offboard_control_mode" not in ulog.message_formats:
            # PX4's logger writes the format of every topic it subscribes at the start, data
            # or not: a log without it was not logging the stream (a profile or a
            # logger_topics.txt that leaves it out, a log cut to other topics). With the format
            # and no data, no offboard source published one: the stream was not sent.
            info.stream_recorded = False
            info.stream_missing = (
                "its logger did not log offboard_control_mode (no format for it: a logger "
                "profile that leaves it out, or a log cut to other topics)"
            )
        if _legacy_flags(datasets):
            info.kinds.add(ev.FailsafeFlags.kind)
        info.kinds.add(ev.VehicleInfo.kind)
        if ulog.initial_parameters or ulog.changed_parameters:
            info.kinds.add(ev.Parameter.kind)
        if ulog.logged_messages or ulog.logged_messages_tagged:
            info.kinds.add(ev.StatusText.kind)
        if ulog.dropouts:
            info.kinds.add(ev.Dropout.kind)
            total_ms = sum(d.duration for d in ulog.dropouts)
            info.notes.append(f"the logger dropped data {len(ulog.dropouts)} times ({total_ms} ms)")
        if info.sampled_intervals:
            info.notes.append(
                "keep-alive and setpoint topics are subsampled by PX4's logger: "
                + ", ".join(
                    f"{k} every {v:.3f} s" for k, v in sorted(info.sampled_intervals.items())
                )
            )
        self._total = info.message_count
        self._info = info
        return info

    def _identity(self, ulog: Any, info: RecordingInfo, status: Any) -> None:
        release = ulog.msg_info_dict.get("ver_sw_release")
        info.px4_version = decode_release(int(release)) if isinstance(release, int) else None
        branch = ulog.msg_info_dict.get("ver_sw_branch")
        info.px4_branch = branch.strip() or None if isinstance(branch, str) else None
        params = dict(ulog.initial_parameters)
        from_params, why = vehicle_from_params(params)
        from_status = _vehicle_from_status(status) if status is not None else None
        vehicle = from_status
        if from_status == "rover":
            rover_param = from_params if from_params and from_params.startswith("rover") else None
            vehicle = rover_param or "rover-differential"
            if rover_param is None:
                info.notes.append("rover drive not recorded (no CA_AIRFRAME): assumed differential")
        elif vehicle is None:
            vehicle = from_params
            if vehicle is not None:
                info.notes.append(f"vehicle type from parameters ({why})")
        info.vehicle_type = vehicle

    # -- events ----------------------------------------------------------------------------

    def events(self) -> Iterator[ev.Event]:
        if self._failed is not None:
            return  # already reported by probe()
        info = self.probe()
        ulog = self._load().ulog
        t0 = int(ulog.start_timestamp)
        context = self._context(info)
        specs = TOPICS
        ranks = {name: rank for rank, name in enumerate(specs, start=10)}
        topics: list[_Stream] = []
        datasets = self._datasets()
        self.set_start(_utc_start(datasets, t0))
        self.aside.read((int(ulog.last_timestamp) - t0) / 1e6)  # the last row, event or not
        windows = None if self.every_row else windows_for(datasets)
        rows_read = self._load().rows_read
        for d in datasets:
            spec = specs.get(d.name)
            if spec is None:
                continue
            rank = ranks[d.name] * 256 + d.multi_id
            topic = d.name if d.multi_id == 0 else f"{d.name}_{d.multi_id}"
            keep = _rows(windows, d, spec.kind)
            read = rows_read.get((d.name, d.multi_id))
            plotted = spec.kind == ev.VehiclePosition.kind and self.aside.plot is not None
            if read is not None and (
                keep is None or plotted or not bool(np.isin(keep, read, kind="table").all())
            ):
                # ``_ReadRows`` decides as this loop does, and ``_load`` reads every row for
                # the plots, so this is not expected (a plot asked for after ``open``): the
                # file is read again, every row decoded (the load had found nothing wrong, so
                # there is nothing to take back from ``problems``)
                self._loaded, self._info, self._whole = None, None, True
                yield from self.events()
                return
            if spec.kind == ev.VehiclePosition.kind and self.aside.plot is not None:
                others = _others(keep, len(d.data["timestamp"]))
                self._plot(_stream(d.data, topic, rank, t0, spec.decode, context, others))
            topics.append(_stream(d.data, topic, rank, t0, spec.decode, context, keep))
        legacy = _legacy_flags(datasets)
        if legacy is not None:
            rank = (len(ranks) + 10) * 256
            topics.append(_stream(legacy.data, "vehicle_status", rank, t0, failsafe_flags, context))
        records = _Stream.of(self._records(ulog, t0))
        streams = [_Stream.of(self._preamble(ulog, info)), *topics, records]
        self._total = sum(len(s.keys) for s in streams)  # the events to come (progress)
        try:
            yield from self._merge(streams)
        except (KeyError, ValueError, TypeError, IndexError, OverflowError) as exc:
            # A layout no release has (a damaged format record that still parsed).
            where = f"the event after the first {self._yielded}"
            raise SourceError(self.path, f"cannot decode the data ({exc!r})", where) from None

    def _plot(self, thinned: _Stream) -> None:
        """Hand the positions thinned out of the events to the plots (``aside.plot``)."""
        assert self.aside.plot is not None
        for event in thinned.events:
            if isinstance(event, ev.VehiclePosition):
                self.aside.plot.position(event)

    def _merge(self, streams: list[_Stream]) -> Iterator[ev.Event]:
        """The streams' events by (time, rank, index), as ``heapq.merge`` of the keyed streams.

        The order is worked out on the keys alone, in numpy (``_merged_order``), and the events
        are taken from their streams in that order. Each stream is advanced exactly when
        ``heapq.merge`` would advance it (all primed first; one read after its event is
        consumed), so even a decoder raising mid-way stops at the same event.
        """
        order = _merged_order(streams)
        if order is None:  # keys numpy cannot order exactly: heapq.merge itself
            for _key, _rank, _index, event in heapq.merge(*(s.keyed() for s in streams)):
                self._yielded += 1
                yield event
            return
        iters = [iter(s.events) for s in streams]
        heads: list[Any] = [next(it, None) for it in iters]
        yielded = self._yielded
        try:
            for start in range(0, len(order), CHUNK_ROWS):
                for s in order[start : start + CHUNK_ROWS].tolist():
                    yielded += 1
                    yield heads[s]
                    heads[s] = next(iters[s], None)
                self._yielded = yielded  # for progress(), once a chunk
        finally:
            self._yielded = yielded  # exact, also when a decoder raised

    def _context(self, info: RecordingInfo) -> Context:
        context = Context()
        release = None
        if info.px4_version:
            try:
                release = releases.get(px4_profile_for(info.px4_version))
            except ProfileError:
                release = None
        if release is not None:
            context.legacy_arming = release.armed_error_state
        else:
            context.legacy_arming = ev.LegacyControlMode.kind in info.kinds
        commander = next((d for d in self._datasets() if d.name == "commander_state"), None)
        if commander is not None and "main_state" in commander.data:
            ts = commander.data["timestamp"]
            order = np.argsort(ts, kind="stable")
            context.intention_ts = ts[order]
            context.intention_nav = [
                MAIN_STATE_TO_NAV.get(m) for m in commander.data["main_state"][order].tolist()
            ]
        return context

    def _preamble(self, ulog: Any, info: RecordingInfo) -> Iterator[tuple[int, int, int, ev.Event]]:
        t0 = int(ulog.start_timestamp)
        mav_type = ulog.initial_parameters.get("MAV_TYPE")
        yield (
            _SORTED_FIRST,
            0,
            0,
            ev.VehicleInfo(
                t=0.0,
                where=ev.Where("info"),
                sender_time_us=t0,
                px4_version=info.px4_version,
                vehicle_type=info.vehicle_type,
                mav_type=int(mav_type) if mav_type is not None else None,
            ),
        )
        for index, (name, value) in enumerate(sorted(ulog.initial_parameters.items())):
            yield (
                _SORTED_FIRST,
                1,
                index,
                ev.Parameter(
                    t=0.0,
                    where=ev.Where("parameters", index),
                    sender_time_us=t0,
                    name=name,
                    value=float(value),
                ),
            )

    def _records(self, ulog: Any, t0: int) -> Iterator[tuple[int, int, int, ev.Event]]:
        """Changed parameters, logged messages and dropouts: records with a time but no topic.
        pyulog dates parameter changes and dropouts at the last data message before them."""
        items: list[tuple[int, int, int, ev.Event]] = []
        for index, (ts, name, value) in enumerate(ulog.changed_parameters):
            event: ev.Event = ev.Parameter(
                t=_seconds(ts, t0),
                where=ev.Where("changed_parameters", index),
                sender_time_us=int(ts),
                name=name,
                value=float(value),
            )
            items.append((int(ts), _RECORD_RANK + 1, index, event))
        logged = list(ulog.logged_messages)
        for tagged in ulog.logged_messages_tagged.values():
            logged.extend(tagged)
        for index, message in enumerate(sorted(logged, key=lambda m: m.timestamp)):
            event = ev.StatusText(
                t=_seconds(message.timestamp, t0),
                where=ev.Where("logged_messages", index),
                sender_time_us=int(message.timestamp),
                severity=_severity(message.log_level),
                text=message.message,
            )
            items.append((int(message.timestamp), _RECORD_RANK + 2, index, event))
        for index, dropout in enumerate(ulog.dropouts):
            event = ev.Dropout(
                t=_seconds(dropout.timestamp, t0),
                where=ev.Where("dropouts", index),
                sender_time_us=int(dropout.timestamp),
                duration_s=dropout.duration / 1000.0,
            )
            items.append((int(dropout.timestamp), _RECORD_RANK + 3, index, event))
        items.sort(key=lambda item: item[:3])
        yield from items

    def progress(self) -> float | None:
        if not self._total:
            return None
        return min(1.0, self._yielded / self._total)


def _rows(windows: Windows | None, d: Any, kind: str) -> Any:
    """The rows of topic instance ``d`` (of event ``kind``) a lint reads; None: all."""
    if kind == ev.VehiclePosition.kind:
        return _one_per_period(d.data["timestamp"], POSITION_PERIOD_S)
    return windows.rows(d.data, kind) if windows is not None else None


class _ReadRows:
    """The rows ``events`` reads, told to the load before pyulog decodes them (``framing``):
    the windows come from the status and declarations, decoded first."""

    first: tuple[str, ...] = ("vehicle_status", "offboard_control_mode")

    def __init__(self) -> None:
        self.windows: Windows | None = None

    def prepare(self, datasets: list[Any]) -> None:
        self.windows = windows_for(
            [d for d in datasets if "timestamp" in d.data and len(d.data["timestamp"])]
        )

    def thinned(self, name: str) -> bool:
        spec = TOPICS.get(name)
        return spec is not None and (
            spec.kind == ev.VehiclePosition.kind or spec.kind in THINNED_KINDS
        )

    def rows(self, name: str, timestamps: Any) -> Any:
        spec = TOPICS.get(name)
        if spec is None:
            return None
        return _rows(self.windows, _Columns(name, {"timestamp": timestamps}), spec.kind)


class _Columns:
    """A topic instance's columns, as pyulog's ``Data`` holds them (``name``, ``data``)."""

    __slots__ = ("data", "name")

    def __init__(self, name: str, data: dict[str, Any]) -> None:
        self.name = name
        self.data = data


def _utc_start(datasets: list[Any], t0: int) -> float | None:
    """The log's start on the wall clock from the first GPS fix that carries a UTC time."""
    for d in datasets:
        if d.name in GPS_TOPICS and "time_utc_usec" in d.data:
            utc = d.data["time_utc_usec"]
            found = np.flatnonzero(utc > 0)
            if len(found):
                i = int(found[0])
                return (int(utc[i]) - (int(d.data["timestamp"][i]) - t0)) / 1e6
    return None


def _drop_renamed_fields(ulog: Any) -> list[SourceProblem]:
    """Topics whose format names a field one character away from one fuzzoff reads (see
    ``renamed_fields``): set aside, one line each, as a format damaged in any other way."""
    problems = []
    kept = []
    for data in ulog.data_list:
        spec = TOPICS.get(data.name)
        decode = spec.decode if spec is not None else None
        renamed = renamed_fields(data.data, decode, EXTRA_FIELDS.get(data.name, ()))
        if not renamed:
            kept.append(data)
            continue
        wanted, found = renamed[0]
        what = (
            f"damaged format record of {quoted(data.name)} (a field {quoted(found)} where "
            f"{quoted(wanted)} belongs, one character apart); its messages were not read"
        )
        start = ulog.format_offsets.get(data.name)
        problems.append(SourceProblem(what, f"byte {start}" if start is not None else None))
    ulog.data_list[:] = kept
    return problems


def _seconds(ts: int, t0: int) -> float:
    return max(0.0, (int(ts) - t0) / 1e6)


def _severity(level: int) -> int:
    """ULog log levels are the ASCII digits '0'..'7' (syslog severities)."""
    if ord("0") <= level <= ord("7"):
        return level - ord("0")
    return level if 0 <= level <= 7 else 6


def _kind(d: Any) -> str:
    if d.name == "offboard_control_mode" and "ignore_thrust" in d.data:
        return ev.LegacyControlMode.kind
    return TOPICS[d.name].kind


def _interval(timestamps: Any, default: float | None) -> float | None:
    """The logger's interval for a topic: the median gap between logged samples, but never
    more than PX4's default logging interval (a slower stream is logged whole)."""
    if len(timestamps) < 2:
        return default
    gaps = np.diff(np.sort(timestamps.astype(np.int64)))
    gaps = gaps[gaps > 0]
    if not len(gaps):
        return default
    median = float(np.median(gaps)) / 1e6
    return round(min(median, default) if default is not None else median, 6)


def _vehicle_from_status(status: Any) -> str | None:
    """``vtol``, ``mc``, ``fw`` or ``rover`` (drive not known here) from ``vehicle_status``."""
    data = status.data
    if "is_vtol" in data and bool(np.any(data["is_vtol"] != 0)):
        return "vtol"
    if "vehicle_type" in data:
        types = data["vehicle_type"]
    elif "is_rotary_wing" in data:
        system = data.get("system_type", np.zeros_like(data["is_rotary_wing"]))
        types = np.where(data["is_rotary_wing"] != 0, 1, np.where(system == 10, 3, 2))
    else:
        return None
    known = types[types != 0]
    if not len(known):
        return None
    value = int(known[0])
    if value == 3:
        return "rover"
    return PX4_VEHICLE_TYPE.get(value)


def _legacy_flags(datasets: list[Any]) -> Any:
    """Legacy ``vehicle_status`` carrying the link-loss flags itself, when no flags topic does."""
    if any(d.name in ("failsafe_flags", "vehicle_status_flags") for d in datasets):
        return None
    status = next((d for d in datasets if d.name == "vehicle_status"), None)
    if status is not None and "offboard_control_signal_lost" in status.data:
        return status
    return None


class _Stream:
    """One source of events in merge order: its merge keys (``key``, ``rank``; the index is
    the position) and the events, one per key, made lazily."""

    def __init__(self, keys: Any, rank: int | list[int], index: Any, events: Iterator[ev.Event]):
        self.keys = keys
        """Merge keys (time, us) in stream order: a numpy array or a list of ints."""
        self.rank = rank
        """The stream's rank, or one per event (records, preamble)."""
        self.index = index
        """Each event's row in its topic (None: rows in file order, the usual case)."""
        self.events = events

    @classmethod
    def of(cls, items: Iterator[tuple[int, int, int, ev.Event]]) -> _Stream:
        """A stream of already keyed items (few: the preamble and the records)."""
        listed = list(items)
        return cls(
            [item[0] for item in listed],
            [item[1] for item in listed],
            [item[2] for item in listed],
            iter([item[3] for item in listed]),
        )

    def keyed(self) -> Iterator[tuple[int, int, int, ev.Event]]:
        """(key, rank, index, event) tuples, for ``heapq.merge``."""
        keys = self.keys.tolist() if isinstance(self.keys, np.ndarray) else self.keys
        ranks = self.rank if isinstance(self.rank, list) else repeat(self.rank)
        index = self.index
        if index is None:  # rows in file order
            index = range(len(keys))
        elif isinstance(index, np.ndarray):
            index = index.tolist()
        return zip(keys, ranks, index, self.events, strict=False)


def _merged_order(streams: list[_Stream]) -> Any:
    """Which stream each merged event comes from, in ``heapq.merge`` order; None when numpy
    cannot decide it exactly (the caller then merges with ``heapq.merge``).

    The first stream is the preamble (key -1: before everything, in its own order); the last
    one holds the records (ranks above every topic's). The topic streams are each sorted by
    (key, index), with distinct ranks: so a stable sort by key of the streams laid end to end in
    rank order is the (key, rank, index) order.
    """
    preamble, *middle, records = streams
    ranks = [s.rank for s in middle if isinstance(s.rank, int)]
    if (
        len(ranks) != len(middle)
        or len(set(ranks)) != len(ranks)
        or max(ranks, default=0) >= _RECORD_RANK
    ):
        return None
    topics = [s for _, s in sorted(zip(ranks, middle, strict=True), key=lambda item: item[0])]
    if any(k != _SORTED_FIRST for k in preamble.keys):
        return None
    if not all(s.keys.dtype.kind == "u" for s in topics):
        return None  # a damaged format with a signed or float timestamp
    if any(not 0 <= k < 1 << 64 for k in records.keys):
        return None
    position = {id(s): n for n, s in enumerate(streams)}
    keys = [s.keys.astype(np.uint64, copy=False) for s in topics]
    keys.append(np.array(records.keys, dtype=np.uint64))
    owner = [position[id(s)] for s in topics] + [len(streams) - 1]
    which = np.repeat(np.array(owner, dtype=np.int32), [len(k) for k in keys])
    merged = which[np.argsort(np.concatenate(keys), kind="stable")]
    return np.concatenate([np.zeros(len(preamble.keys), dtype=np.int32), merged])


def _one_per_period(ts: Any, period_s: float) -> Any:
    """The rows to read of a topic thinned to one per ``period_s``: the first logged row of
    each period of the log's clock (a row's ``where`` index still names its logged place)."""
    with np.errstate(all="ignore"):
        bucket = ts.astype(np.float64) // (period_s * 1e6)
    _, first = np.unique(bucket, return_index=True)
    return np.sort(first)


def _stream(
    cols: Any,
    topic: str,
    rank: int,
    t0: int,
    decode: Any,
    context: Context,
    keep: Any = None,
) -> _Stream:
    """One topic instance's events in timestamp order, made a chunk at a time (``keep``: only
    those rows)."""
    ts = cols["timestamp"]
    n = len(ts)
    order: Any = None
    if keep is not None:
        order = keep[np.argsort(ts[keep], kind="stable")]
        n = len(order)
    elif n > 1 and bool(np.any(ts[1:] < ts[:-1])):
        order = np.argsort(ts, kind="stable")
    keys = ts if order is None else ts[order]
    return _Stream(keys, rank, order, _chunks(cols, order, n, topic, t0, decode, context))


def _chunks(
    cols: Any, order: Any, n: int, topic: str, t0: int, decode: Any, context: Context
) -> Iterator[ev.Event]:
    """The events of ``decode`` chunk after chunk, chained by ``itertools.chain`` (no Python
    frame per event between the merge and the decoder); each chunk is made when the one
    before it is used up, as a generator would."""
    selections = (
        slice(start, min(n, start + CHUNK_ROWS))
        if order is None
        else order[start : start + CHUNK_ROWS]
        for start in range(0, n, CHUNK_ROWS)
    )
    return chain.from_iterable(
        decode(Chunk(cols, sel, topic, t0), context)  # one event per row
        for sel in selections
    )


def _others(rows: Any, n: int) -> Any:
    """The rows of a topic of ``n`` rows that are not in ``rows``."""
    return np.setdiff1d(np.arange(n), rows, assume_unique=True)
