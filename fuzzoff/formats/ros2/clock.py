"""When an MCAP started on the wall clock (for the fleet table): its statistics, else its first
message's log time (Unix nanoseconds)."""

from __future__ import annotations

from pathlib import Path


def mcap_start_s(path: Path) -> float | None:
    from mcap.reader import make_reader

    with path.open("rb") as fh:
        reader = make_reader(fh)
        summary = reader.get_summary()
        if summary is not None and summary.statistics is not None:
            if summary.statistics.message_count:
                return summary.statistics.message_start_time / 1e9
            return None
        for _schema, _channel, message in reader.iter_messages(log_time_order=False):
            return float(message.log_time) / 1e9
    return None
