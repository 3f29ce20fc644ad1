"""Cut real PX4 ULogs (pyulog's own test logs, BSD-3-Clause) down to what fuzzoff reads.

Run ``.venv/bin/python corpora/real/cut.py SOURCE.ulg...``: for each log, pyulog loads only the
topics fuzzoff's ULog reader loads for the HTML report (``PLOT_LOADED_TOPICS``: what lint reads,
plus the vehicle's local position and GPS for the plots) and writes them back with
``ULog.write_ulog``, keeping the header, info, parameters and logged messages, so the cut log
stays under 1 MB and says to fuzzoff exactly what the original says. Provenance: README.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

from pyulog import ULog

from fuzzoff.formats.ulog.reader import PLOT_LOADED_TOPICS

HERE = Path(__file__).resolve().parent


def cut(source: Path) -> Path:
    log = ULog(str(source), message_name_filter_list=list(PLOT_LOADED_TOPICS))
    target = HERE / source.name
    log.write_ulog(str(target))
    return target


if __name__ == "__main__":
    for name in sys.argv[1:]:
        path = cut(Path(name))
        print(f"{path.name}: {path.stat().st_size} bytes")
