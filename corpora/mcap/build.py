"""Build the MCAP corpus: PX4 ROS 2 (uXRCE-DDS) offboard flights as rosbag2's MCAP plugin
would record them (formats.md 2, 4).

Run ``.venv/bin/python corpora/mcap/build.py``; it is deterministic. Every recording is written
through ``fuzzoff.formats.mcap.writer`` (mcap_ros2 encodes, px4_msgs definitions embedded) from the
flights in ``flights.py``, and gets ``NAME.expected.json`` with the findings planted here, judged
against the rule texts (rules/OFB*.toml). Every flight is PX4 1.15 on a multicopter (the
release is told by the embedded definitions, the type by ``VehicleStatus.vehicle_type``), so
each also carries two context findings: OFB002 (OFB305 needs estimator flags a ROS 2 recording
of these topics lacks) and OFB701 (the loss parameters assumed, at the offboard request).

* ``good_flight``: OffboardControlMode at 20 Hz for 2 s, accepted switch, setpoints only in
  offboard, NAV_LAND; nothing else.
* ``keepalive_gap_0_7s``: OffboardControlMode pauses 0.75 s in offboard (setpoints go on):
  OFB101 info (under 80 % of COM_OF_LOSS_T = 1 s: PX4 1.15 keeps offboard, the docs' 2 Hz only).
* ``stream_lost``: the program stalls for 3.55 s in offboard (both topics stop); PX4's status
  shows POSCTL from 7.0 s: OFB101 error and OFB103 at the loss (5.95 s + 1 s).
* ``switch_50ms_after_first_ocm``: the switch 50 ms after the first OffboardControlMode:
  OFB102 info (PX4 1.15 accepts it: no release enforces the docs' second).
* ``switch_rejected``: the ack says TEMPORARILY_REJECTED: OFB201, and OFB202 as the gate model
  expected PX4 1.15 to accept a switch after 2 s of stream.
* ``wrong_release_payload``: the good flight whose VehicleControlMode payloads are 1.15's while
  the embedded definitions are 1.18's (profile 1.18): OFB001 at its first message (never
  decoded half-right); exit status 2, the other topics' findings kept.
* ``truncated``: the stream-lost flight cut in its last chunk: OFB001 (no footer), exit status
  2; the findings of the readable part (OFB101, OFB103) are kept.
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from flights import Flight  # noqa: E402
from mcap.reader import SeekingReader  # noqa: E402

from fuzzoff.events import Event, VehicleControlModeStatus  # noqa: E402
from fuzzoff.formats.mcap.writer import write_mcap  # noqa: E402

RELEASE = "1.15"
CONTEXT = [
    {"code": "OFB002", "severity": "info", "time_s": None},
    {"code": "OFB701", "severity": "info", "time_s": 2.0},
]


def finding(code: str, severity: str, t: float | None, vehicle: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {"code": code, "severity": severity, "time_s": t}
    if vehicle:
        out["vehicle"] = vehicle
    return out


def control_modes(flight: Flight) -> list[Event]:
    """VehicleControlMode at 2 Hz (offboard enabled while the status says OFFBOARD)."""
    out: list[Event] = []
    for k in range(int(flight.end * 2)):
        t = k * 0.5 + 0.25
        offboard = flight.mode_at(t) == 14
        enabled = {"offboard", "position", "velocity", "altitude"} if offboard else {"position"}
        out.append(
            VehicleControlModeStatus(
                t=t,
                vehicle=flight.vehicle,
                sender_time_us=round(t * 1e6) + 5_000_000,
                offboard_enabled=offboard,
                enabled=frozenset(enabled),
            )
        )
    return out


def write_expected(
    name: str,
    recording: str,
    findings: list[dict[str, Any]],
    *,
    exit_status: int,
    complete: bool = True,
    args: list[str] | None = None,
    px4: str = "1.15",
) -> None:
    spec = {
        "recording": recording,
        "args": args or [],
        "exit_status": exit_status,
        "complete": complete,
        "profile": {"px4": px4, "vehicle": "mc", "detected": True},
        "findings": findings,
    }
    (HERE / f"{name}.expected.json").write_text(json.dumps(spec, indent=2) + "\n")


def main() -> None:
    lost = Flight(gaps=[(6.0, 9.5)], lost_mode_at=7.0)
    cases: list[tuple[str, Flight, list[dict[str, Any]], int]] = [
        ("good_flight", Flight(), [], 0),
        (
            "keepalive_gap_0_7s",
            Flight(ocm_gaps=[(6.0, 6.7)]),
            # 70 % of COM_OF_LOSS_T: the docs' 2 Hz alone, PX4 keeps the signal (info)
            [finding("OFB101", "info", 5.95)],
            0,
        ),
        (
            "stream_lost",
            lost,
            [finding("OFB101", "error", 5.95), finding("OFB103", "error", 7.01)],
            1,
        ),
        (
            "switch_50ms_after_first_ocm",
            Flight(switch_at=0.05),
            # the docs' second, which no release enforces: PX4 accepts the switch (info)
            [finding("OFB102", "info", 0.05)],
            0,
        ),
        (
            "switch_rejected",
            Flight(ack_result=1),
            [finding("OFB201", "error", 2.01), finding("OFB202", "warning", 2.01)],
            1,
        ),
    ]
    for name, flight, planted, status in cases:
        write_mcap(HERE / f"{name}.mcap", flight.events(), release=RELEASE)
        context = [dict(c) for c in CONTEXT]
        if flight.switch_at != 2.0:
            context[1]["time_s"] = flight.switch_at
        write_expected(name, f"{name}.mcap", context + planted, exit_status=status)

    good = Flight()
    write_mcap(
        HERE / "wrong_release_payload.mcap",
        good.events() + control_modes(good),
        release="main",
        payload_release={"VehicleControlMode": RELEASE},
    )
    write_expected(
        "wrong_release_payload",
        "wrong_release_payload.mcap",
        [finding("OFB001", "error", 0.25), *CONTEXT],
        exit_status=2,
        complete=False,
        px4="1.18",
    )

    path = write_mcap(HERE / "truncated.mcap", lost.events(), release=RELEASE, chunk_size=2048)
    data = path.read_bytes()
    # Cut in the middle of the last chunk: a cut in the summary after it loses no message
    # (corpora/damaged says so, as OFB004).
    summary = SeekingReader(io.BytesIO(data)).get_summary()
    assert summary is not None
    last = max(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    path.write_bytes(data[: last.chunk_start_offset + last.chunk_length // 2])
    write_expected(
        "truncated",
        "truncated.mcap",
        [
            finding("OFB001", "error", None),
            *CONTEXT,
            finding("OFB101", "error", 5.95),
            finding("OFB103", "error", 7.01),
        ],
        exit_status=2,
        complete=False,
    )


if __name__ == "__main__":
    main()
