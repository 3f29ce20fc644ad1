"""The gate model against real PX4, per release, from the recorded runs in this folder.

    .venv/bin/python -m corpora.sitl.agreement

For every run with a tlog and a ULog, ``fuzzoff.sitl.verdict.compare`` puts the model (run on
the client's tlog, for the run's release) beside PX4's ULog; this counts, per release, the
switches and arms judged and agreed, the losses and their timing (PX4's flag against the
model's instant: within one 10 Hz check period), the failsafe actions and the automatic
returns, the sticks ending OFFBOARD (1.18+), and lists every disagreement.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

from fuzzoff.sitl.airframes import AIRFRAMES, DEFAULT, airframe_for
from fuzzoff.sitl.link import COMPANION_SYSID
from fuzzoff.sitl.verdict import compare

HERE = Path(__file__).resolve().parent
GROUPS = {
    "arm": "requests",
    "disarm": "requests",
    "loss time": "loss time",
    "offboard loss": "loss time",
    "failsafe action": "failsafe action",
    "automatic return": "automatic return",
    "stick override": "stick override",
}


def _release_order(release: str) -> tuple[int, ...]:
    """Releases by version; a build of main (``main-2026-08-13``) after them all."""
    base = release.split("-")[0]
    if not base.replace(".", "").isdigit():
        return (999,)
    return tuple(int(n) for n in base.split("."))


def main() -> None:
    runs = json.loads((HERE / "runs.json").read_text())
    table: dict[tuple[str, str], dict[str, list[int]]] = defaultdict(
        lambda: defaultdict(lambda: [0, 0])
    )
    offsets: dict[tuple[str, str], list[float]] = defaultdict(list)
    differ: list[str] = []
    for stem, run in sorted(runs.items()):
        tlog, ulog = HERE / f"{stem}.tlog", HERE / f"{stem}.ulg"
        if not (tlog.exists() and ulog.exists()):
            continue
        release = run["release"]
        flown = run.get("vehicle", DEFAULT)
        vehicle = airframe_for(flown).fuzzoff_vehicle
        verdict = compare(
            tlog, release.split("-")[0], ulog, run.get("params") or {}, COMPANION_SYSID, vehicle
        )
        for item in verdict.items:
            if item.agree is None:
                continue
            group = GROUPS.get(item.what, "requests" if item.what.startswith("switch") else "other")
            cell = table[(release, flown)][group]
            cell[0] += 1
            cell[1] += int(item.agree)
            if item.what == "loss time" and "ms from PX4's flag" in item.note:
                offsets[(release, flown)].append(float(item.note.split()[1]))
            if not item.agree:
                differ.append(
                    f"{stem}: {item.what} at {item.t:.2f} s: PX4 {item.px4}; model {item.model}"
                )
    columns = [
        "requests",
        "loss time",
        "failsafe action",
        "automatic return",
        "stick override",
        "other",
    ]
    print("| PX4 | vehicle | " + " | ".join(columns) + " | model - PX4 flag (ms) |")
    print("| --- | --- |" + " --- |" * (len(columns) + 1))
    order = list(AIRFRAMES)
    for key in sorted(
        table,
        key=lambda k: (
            _release_order(k[0]),
            k[0],
            order.index(k[1]),
        ),
    ):
        cells = [
            f"{table[key][c][1]}/{table[key][c][0]}" if table[key][c][0] else "-" for c in columns
        ]
        spread = offsets[key]
        span = f"{min(spread):+.0f} to {max(spread):+.0f}" if spread else "-"
        print(f"| {key[0]} | {key[1]} | " + " | ".join(cells) + f" | {span} |")
    print()
    for line in differ:
        print(f"- {line}")


if __name__ == "__main__":
    main()
