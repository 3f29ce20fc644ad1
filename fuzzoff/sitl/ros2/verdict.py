"""The gate model against PX4's own log, for a flight over the ROS 2 bridge.

As ``fuzzoff.sitl.verdict.compare`` does for a MAVLink flight's tlog: the model runs on the
companion's bag (``fuzzoff gate``'s rows) and each request, loss and failsafe it predicts is
judged against PX4's ULog. The bag's times are put on PX4's clock as ``lint --with`` puts them
(``fuzzoff.bridge.clock``: the bridge's time sync and PX4's outputs in both files). The model
sees what the companion sent: where the bridge did not deliver it (an agent restart, OFB108) the
model and PX4 differ, and that difference is the finding, not the model's error.
"""

from __future__ import annotations

from pathlib import Path

from fuzzoff.bridge.bag import read_bag
from fuzzoff.bridge.clock import measure
from fuzzoff.bridge.ulog import read_ulog
from fuzzoff.sitl.truth import read_truth
from fuzzoff.sitl.verdict import (
    Verdict,
    _gate_disagreements,
    _losses,
    _requests,
    _stick_overrides,
    model_rows,
)

STATUS = {"vehicle_status", "failsafe_flags", "vehicle_control_mode", "vehicle_command_ack"}


def compare(
    bag: Path, release: str, ulog: Path, params: dict[str, float] | None = None, vehicle: str = "mc"
) -> Verdict:
    params = params or {}
    recorded = read_bag(bag)
    clock = measure(recorded, read_ulog(ulog, STATUS))
    verdict = Verdict(release, "ulog")
    rows, problems = model_rows(bag, release, params, vehicle)
    verdict.problems += problems
    for row in rows:
        row["px4_t"] = clock.px4_us(recorded.first_us + row["time_s"] * 1e6) / 1e6
    truth = read_truth(ulog)
    _requests(verdict, truth, rows)
    _stick_overrides(verdict, truth, rows)
    _losses(verdict, truth, rows, params.get("COM_OF_LOSS_T", 1.0), True)
    _gate_disagreements(verdict, rows)
    verdict.items.sort(key=lambda i: i.t)
    return verdict
