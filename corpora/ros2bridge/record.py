"""Record the ROS 2 bridge corpus: px4_ros_com's offboard_control flown on real PX4 over DDS.

Run from the repository root with a Python that has the ``ros2live`` extra (cyclonedds), as
root (each flight runs in its own network namespace, ``fuzzoff.sitl.ros2.netns``):

    python corpora/ros2bridge/record.py [PROGRAM-BUNDLE ...]
    python corpora/ros2bridge/record.py --from DIR PROGRAM-BUNDLE ...

(when none is named: every run of ``RUNS``). ``--from DIR`` takes flights already flown by
``fuzzoff sitl run PROGRAM --transport ros2 --release BUNDLE --save-dir DIR`` (the same flight,
``netns.run_flight``, with the same outputs) instead of flying them again: a flight that showed
something worth keeping (a time sync jump) is kept as it was. Each run boots a fresh PX4 with
the Micro XRCE-DDS Agent (``../shared/px4-sitl/``) and leaves beside this file:

- ``PROGRAM-BUNDLE-mcap/``, ``PROGRAM-BUNDLE-sqlite3/``: the bag of the flight, as
  ``ros2 bag record`` writes it, in both storages (``fuzzoff.sitl.ros2.bag``);
- ``PROGRAM-BUNDLE.ulg``: PX4's own log from boot to exit, cut to the topics fuzzoff reads;
- an entry in ``runs.json``: PX4's answers (acks, mode changes on the node's clock, counted
  from its start), each topic's message count and the QoS its writers offered.

The expected findings are written separately (``expected.py``).
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent))

from pyulog import ULog  # noqa: E402

from fuzzoff.formats.ulog.reader import LOADED_TOPICS  # noqa: E402
from fuzzoff.sitl.ros2.netns import run_flight  # noqa: E402
from fuzzoff.sitl.trim import ALIGN_TOPICS  # noqa: E402

RUNS: tuple[tuple[str, str], ...] = (
    ("example", "1.16.2-ros2"),
    ("example", "1.18.0-beta1-head"),
    ("example_stops", "1.16.2-ros2"),
    ("example_stops", "1.18.0-beta1-head"),
    ("example_lands", "1.16.2-ros2"),
    ("example_lands_through", "1.18.0-beta1-head"),
    ("example_no_setpoint", "1.16.2-ros2"),
    ("example_arm_lost", "1.16.2-ros2"),
    ("example_late_bag", "1.16.2-ros2"),
    ("example_in_only", "1.16.2-ros2"),
    ("example_agent_restart", "1.16.2-ros2"),
    ("example_agent_restart", "1.18.0-beta1-head"),
    *(
        (program, bundle_name)
        for program in (
            "rover_position",
            "rover_speed_steering",
            "rover_speed_attitude",
            "rover_throttle_steering",
            "rover_trajectory",
            "rover_speed_alone",
            "rover_throttle_velocity_flag",
            "rover_stops",
        )
        for bundle_name in ("1.17.0-ros2-rover", "1.18.0-beta1-head")
    ),
    ("ext_mode", "1.18.0-beta1-head"),
    ("ext_mode_old_api", "1.18.0-beta1-head"),
    ("ext_mode_dies", "1.18.0-beta1-head"),
    ("ext_mode", "1.17.0-ros2-rover"),
    ("ext_mode_old_api", "1.17.0-ros2-rover"),
    *(
        (program, bundle_name)
        for program in ("vtol_transition", "vtol_stops", "fw_ground_gate")
        for bundle_name in (
            "1.18.0-beta1-head",
            "1.16.2-ros2",
            "1.17.0-ros2-rover",
            "main-2026-08-13",
        )
    ),
)
"""(program of ``fuzzoff.sitl.ros2.programs``, bundle): one PX4 boot each."""
MAX_BYTES = 1_000_000
LEFT_OUT = frozenset({"vehicle_local_position"})
"""Left out of a ULog that is over 1 MB (as ``corpora/sitl/record_mavsdk.py`` does): PX4 logs it
at 100 Hz; the bags keep it."""


def cut_more(ulog: Path) -> None:
    """Without ``LEFT_OUT``, keeping what ``trim`` keeps beside the topics fuzzoff reads (the
    bridge's ``timesync_status``: the offsets PX4 applied, which explain its loss times)."""
    kept = (set(LOADED_TOPICS) | set(ALIGN_TOPICS)) - LEFT_OUT
    log = ULog(str(ulog), message_name_filter_list=sorted(kept))
    log.write_ulog(str(ulog))


def record(program: str, bundle_name: str, flown: Path | None = None) -> dict[str, object]:
    """One flight flown now, or taken from ``flown`` (a ``sitl run --save-dir`` folder)."""
    stem = f"{program}-{bundle_name}"
    for old in (HERE / f"{stem}-mcap", HERE / f"{stem}-sqlite3"):
        shutil.rmtree(old, ignore_errors=True)
    if flown is not None:
        for suffix in ("-mcap", "-sqlite3"):
            shutil.copytree(flown / f"{stem}{suffix}", HERE / f"{stem}{suffix}")
        for suffix in (".ulg", ".json"):
            shutil.copyfile(flown / f"{stem}{suffix}", HERE / f"{stem}{suffix}")
    else:
        done = run_flight(HERE, [program, bundle_name, stem])
        if done.returncode != 0:
            raise SystemExit(f"{stem}: the flight failed:\n{done.stdout}\n{done.stderr}")
    summary_file = HERE / f"{stem}.json"
    summary: dict[str, object] = json.loads(summary_file.read_text())
    summary_file.unlink()
    ulog = HERE / f"{stem}.ulg"
    if ulog.stat().st_size >= MAX_BYTES:
        cut_more(ulog)
        summary["ulog_left_out"] = sorted(LEFT_OUT)
    for path in HERE.glob(f"{stem}*"):
        for file in [path] if path.is_file() else path.iterdir():
            if file.stat().st_size >= MAX_BYTES:
                raise SystemExit(f"{file}: over 1 MB; shorten the program or cut the ULog more")
    return summary


def main(args: list[str]) -> int:
    flown: Path | None = None
    if args[:1] == ["--from"]:
        if len(args) < 3:
            raise SystemExit("--from DIR takes the flights to keep: PROGRAM-BUNDLE ...")
        flown, names = Path(args[1]), args[2:]
    else:
        names = args
    runs_file = HERE / "runs.json"
    runs = json.loads(runs_file.read_text()) if runs_file.exists() else {}
    chosen = [r for r in RUNS if not names or f"{r[0]}-{r[1]}" in names]
    for program, bundle_name in chosen:
        print(f"{program} on {bundle_name} ...", flush=True)
        summary = record(program, bundle_name, flown)
        runs[f"{program}-{bundle_name}"] = summary
        runs_file.write_text(json.dumps(runs, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
