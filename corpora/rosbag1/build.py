"""Build the ROS 1 bag corpus: MAVROS offboard flights, good and bad (run from the repo root).

    .venv/bin/python corpora/rosbag1/build.py

Each recording is written by ``fuzzoff.formats.rosbag1.writer`` (MAVROS ``setpoint_raw/local`` at
20 Hz and ``/mavros/state`` at 1 Hz, as MAVROS publishes it on every HEARTBEAT) and comes with
``NAME.expected.json``: the findings planted, checked against the rule texts. Deterministic.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent))

from fuzzoff.events import Event, SetPositionTargetLocal, VehicleStatus  # noqa: E402
from fuzzoff.formats.rosbag1.writer import write_rosbag1  # noqa: E402
from fuzzoff.modes import mavros_mode_to_nav_state  # noqa: E402

RATE_S = 0.05
"""20 Hz setpoints."""

PROFILE_ARGS = ["--px4", "1.15", "--vehicle", "mc"]
"""MAVROS bags do not say the PX4 version: the bad recordings name it, so OFB003 stays out."""


def states(modes: list[tuple[float, str]], end: float) -> list[Event]:
    """``/mavros/state`` once a second at x.5 s; ``modes`` = (from time, MAVROS mode string)."""
    out: list[Event] = []
    t = 0.5
    while t <= end:
        mode = [m for start, m in modes if start <= t][-1]
        nav = mavros_mode_to_nav_state(mode)
        out.append(VehicleStatus(t=t, nav_state=nav, mode=mode, armed=True))
        t += 1.0
    return out


def setpoints(start: float, end: float, gaps: tuple[tuple[float, float], ...] = ()) -> list[Event]:
    """Position setpoints every 50 ms, skipping ``gaps``: at 2.5 m, walking north at 0.4 m/s."""
    out: list[Event] = []
    i = 0
    while True:
        t = round(start + i * RATE_S, 6)
        if t > end:
            return out
        i += 1
        if any(a < t < b for a, b in gaps):
            continue
        out.append(
            SetPositionTargetLocal(
                t=t,
                target_system=1,
                target_component=1,
                transport="mavros",
                type_mask=0x09F8,
                coordinate_frame=1,
                position=(round(0.4 * t, 3), 0.0, -2.5),
                yaw=0.0,
            )
        )


def flight(modes: list[tuple[float, str]], sp: list[Event], end: float) -> list[Event]:
    return sorted([*states(modes, end), *sp], key=lambda e: e.t)


SUMMARY = {"code": "OFB701", "severity": "info", "time_s": 3.5}
"""Every flight here enters offboard at 3.5 s: the loss-action summary (PX4 defaults) is stated."""


def expected(
    name: str,
    findings: list[dict[str, Any]],
    *,
    exit_status: int,
    args: list[str] | None = None,
    complete: bool = True,
) -> None:
    spec = {
        "recording": f"{name}.bag",
        "args": PROFILE_ARGS if args is None else args,
        "exit_status": exit_status,
        "complete": complete,
        "findings": [SUMMARY, *findings],
    }
    (HERE / f"{name}.expected.json").write_text(json.dumps(spec, indent=2) + "\n")


def main() -> None:
    # Good: setpoints from 1.0 s, OFFBOARD shown at 3.0 s (2 s of 20 Hz stream before), the
    # stream runs on until after the switch to AUTO.LAND at 11 s. No PX4 version in the bag.
    good = flight(
        [(0.0, "POSCTL"), (3.0, "OFFBOARD"), (11.0, "AUTO.LAND")], setpoints(1.0, 12.0), 12.0
    )
    write_rosbag1(HERE / "offboard_good.bag", good)
    expected(
        "offboard_good",
        [{"code": "OFB003", "severity": "info", "time_s": None}],
        exit_status=0,
        args=[],
    )
    # Bad: a 0.8 s gap in offboard (6.0 -> 6.8). OFB101 at the gap's start: 0.8 s > 500 ms, and
    # 80 % of PX4 1.15's COM_OF_LOSS_T (1.0 s): PX4 keeps offboard, but only just (a warning).
    short = flight(
        [(0.0, "POSCTL"), (3.0, "OFFBOARD"), (11.0, "AUTO.LAND")],
        setpoints(1.0, 12.0, gaps=((6.0, 6.8),)),
        12.0,
    )
    write_rosbag1(HERE / "offboard_short_gap.bag", short)
    expected(
        "offboard_short_gap",
        [{"code": "OFB101", "severity": "warning", "time_s": 6.0}],
        exit_status=1,
    )
    # Bad: the companion dies at 6.0 s (stream stops for good) while in offboard. OFB101 at
    # 6.0 s: the next keep-alive never comes (an error: longer than COM_OF_LOSS_T). OFB103: PX4
    # 1.15 declares loss 1.0-1.1 s after the last setpoint (checked at 10 Hz at a phase the bag
    # does not show: 7.0-7.1 s, failsafe by 7.11 s) and falls back to Position (COM_OBL_RC_ACT
    # 0); /mavros/state (1 Hz) shows POSCTL at 7.5 s.
    stop = flight([(0.0, "POSCTL"), (3.0, "OFFBOARD"), (7.0, "POSCTL")], setpoints(1.0, 6.0), 12.0)
    write_rosbag1(HERE / "offboard_stream_lost.bag", stop)
    expected(
        "offboard_stream_lost",
        [
            {"code": "OFB101", "severity": "error", "time_s": 6.0},
            {"code": "OFB103", "severity": "error", "time_s": 7.11},
        ],
        exit_status=1,
    )
    # Setpoints start at 3.0 s, OFFBOARD shown at 3.5 s: 0.5 s of stream before the switch.
    # OFB102 says the docs' second, which no release enforces: PX4 1.15 accepts the switch once
    # its signal is available (info).
    early = flight(
        [(0.0, "POSCTL"), (3.0, "OFFBOARD"), (11.0, "AUTO.LAND")], setpoints(3.0, 12.0), 12.0
    )
    write_rosbag1(HERE / "offboard_switch_early.bag", early)
    expected(
        "offboard_switch_early",
        [{"code": "OFB102", "severity": "info", "time_s": 3.5}],
        exit_status=0,
    )
    # Truncated: the good flight cut in half (a recorder killed mid-write, then the file copied).
    data = (HERE / "offboard_good.bag").read_bytes()
    (HERE / "offboard_truncated.bag").write_bytes(data[: len(data) // 2])
    expected(
        "offboard_truncated",
        [{"code": "OFB001", "severity": "error", "time_s": None}],
        exit_status=2,
        complete=False,
    )


if __name__ == "__main__":
    main()
