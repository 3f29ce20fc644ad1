"""``fuzzoff lint BAG --with ULOG``: the bag's report gets the comparison with PX4's ULog.

Exactly one ROS 2 bag among the linted recordings (the ULog may be linted beside it: name it in
``--with`` too); two files that are not one flight, or that cannot be read, are a usage error:
one line, exit 2 (``fuzzoff.bridge``).
"""

from __future__ import annotations

from pathlib import Path

from fuzzoff.bridge import BridgeError
from fuzzoff.bridge.bag import read_bag
from fuzzoff.bridge.compare import compare
from fuzzoff.bridge.report import findings
from fuzzoff.bridge.ulog import read_ulog
from fuzzoff.config import ConfigError
from fuzzoff.findings import Report

BAGS = ("rosbag2-mcap", "rosbag2-sqlite3")
STATUS = {"vehicle_status", "failsafe_flags"}


def add_delivery(report: Report, ulog: Path) -> None:
    bags = [f for f in report.files if f.format in BAGS]
    if len(bags) != 1:
        raise ConfigError(
            f"--with compares one ROS 2 bag folder with PX4's ULog; {len(bags)} bags were named"
        )
    (file,) = bags
    if not ulog.is_file():
        raise ConfigError(f"--with {ulog}: no such file")
    try:
        bag = read_bag(Path(file.path))
        delivery = compare(bag, read_ulog(ulog, set(bag.topics) | STATUS))
    except BridgeError as exc:
        raise ConfigError(str(exc)) from None
    file.delivery = delivery
    added = findings(delivery)
    file.findings = sorted(
        [*file.findings, *added],
        key=lambda f: (float("-inf") if f.time_s is None else f.time_s, f.code),
    )
