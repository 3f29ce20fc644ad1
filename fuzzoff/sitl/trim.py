"""A PX4 ULog cut to the topics fuzzoff reads, so that a run's log stays under 1 MB.

pyulog loads only ``fuzzoff.formats.ulog.reader.LOADED_TOPICS`` and writes them back with
``ULog.write_ulog``: header, info, parameters and logged messages (PX4's own texts, such as
"Disarming denied: not landed") are kept, as ``corpora/real/cut.py`` does for public logs.
"""

from __future__ import annotations

from pathlib import Path

from pyulog import ULog

from fuzzoff.formats.ulog.reader import LOADED_TOPICS


def trim(source: Path, target: Path) -> Path:
    log = ULog(str(source), message_name_filter_list=list(LOADED_TOPICS))
    log.write_ulog(str(target))
    return target
