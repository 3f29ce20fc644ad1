"""Build the rosbag2 corpus: PX4 ROS 2 offboard flights in ROS 2 bag folders (formats.md 2, 5).

Run ``.venv/bin/python corpora/rosbag2/build.py``; it is deterministic. Bags are written through
``fuzzoff.formats.rosbag2.writer`` (rosbags' writer) from the flights in
``corpora/mcap/flights.py``; each gets ``NAME.expected.json`` with the findings planted here, judged
against the rule texts. Every flight is on a multicopter; each carries the context findings OFB002
(OFB305 needs estimator flags these topics lack) and OFB701 (loss parameters assumed) at the
offboard request.

* ``good_flight_sqlite3``: PX4 1.18 (profile 1.18; versioned topics ``vehicle_status_v4``,
  ``vehicle_command_ack_v1``), the good flight; nothing else.
* ``stream_lost_mcap``: mcap storage, PX4 1.15, the program stalls 3.55 s in offboard and the
  status shows POSCTL from 7.0 s: OFB101 error and OFB103 at 7.01 s.
* ``two_vehicles``: ``/fmu/...`` flies well; ``/px4_1/fmu/...`` pauses its
  OffboardControlMode for 0.75 s in offboard: OFB101 (info: under 80 % of the loss timeout)
  for vehicle ``/px4_1`` only.
* ``humble_no_definitions``: a Humble-style sqlite bag (schema 3, no message definitions) of a
  PX4 1.14 flight whose switch comes 50 ms after the first OffboardControlMode: the bundled
  1.14 definitions are chosen from the payloads (profile detected), OFB102 (info: PX4 accepts it).
* ``truncated_db3``: the stream-lost flight (sqlite3, 1.15) with its database cut at 80 %:
  rosbags cannot open it, the rows before the cut are salvaged: OFB001, exit status 2, and
  the readable part's findings (OFB101, OFB103) are kept.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "mcap"))

from flights import Flight  # noqa: E402

from fuzzoff.formats.rosbag2.writer import write_rosbag2  # noqa: E402


def finding(code: str, severity: str, t: float | None, vehicle: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {"code": code, "severity": severity, "time_s": t}
    if vehicle:
        out["vehicle"] = vehicle
    return out


def context(switch_at: float = 2.0, vehicle: str = "") -> list[dict[str, Any]]:
    return [finding("OFB002", "info", None), finding("OFB701", "info", switch_at, vehicle)]


def write_expected(
    name: str, findings: list[dict[str, Any]], *, px4: str, exit_status: int, complete: bool = True
) -> None:
    spec = {
        "recording": name,
        "args": [],
        "exit_status": exit_status,
        "complete": complete,
        "profile": {"px4": px4, "vehicle": "mc", "detected": True},
        "findings": findings,
    }
    (HERE / f"{name}.expected.json").write_text(json.dumps(spec, indent=2) + "\n")


def fresh(name: str) -> Path:
    path = HERE / name
    shutil.rmtree(path, ignore_errors=True)
    return path


def main() -> None:
    write_rosbag2(fresh("good_flight_sqlite3"), Flight().events(), release="main")
    write_expected("good_flight_sqlite3", context(), px4="1.18", exit_status=0)

    lost = Flight(gaps=[(6.0, 9.5)], lost_mode_at=7.0)
    write_rosbag2(fresh("stream_lost_mcap"), lost.events(), storage="mcap", release="1.15")
    write_expected(
        "stream_lost_mcap",
        [*context(), finding("OFB101", "error", 5.95), finding("OFB103", "error", 7.01)],
        px4="1.15",
        exit_status=1,
    )

    second = Flight(vehicle="/px4_1", ocm_gaps=[(6.0, 6.7)])
    write_rosbag2(fresh("two_vehicles"), Flight().events() + second.events(), release="1.15")
    write_expected(
        "two_vehicles",
        [
            *context(),
            finding("OFB701", "info", 2.0, "/px4_1"),
            finding("OFB101", "info", 5.95, "/px4_1"),  # 0.7 s: under 80 % of COM_OF_LOSS_T
        ],
        px4="1.15",
        exit_status=0,
    )

    early = Flight(switch_at=0.05)
    write_rosbag2(fresh("humble_no_definitions"), early.events(), release="1.14", definitions=False)
    write_expected(
        "humble_no_definitions",
        [*context(0.05), finding("OFB102", "info", 0.05)],  # PX4 1.14 accepts the switch
        px4="1.14",
        exit_status=0,
    )

    bag = write_rosbag2(fresh("truncated_db3"), lost.events(), release="1.15")
    db3 = next(bag.glob("*.db3"))
    data = db3.read_bytes()
    db3.write_bytes(data[: len(data) * 8 // 10])
    write_expected(
        "truncated_db3",
        [
            finding("OFB001", "error", None),
            *context(),
            finding("OFB101", "error", 5.95),
            finding("OFB103", "error", 7.01),
        ],
        px4="1.15",
        exit_status=2,
        complete=False,
    )


if __name__ == "__main__":
    main()
