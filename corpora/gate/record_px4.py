"""Record what real PX4 does with a disarm in flight, an arm while armed and repeated losses.

Run ``.venv/bin/python corpora/gate/record_px4.py --bundle ../shared/px4-sitl/1.15.4
[--instance 6]`` (see ``../shared/px4-sitl/README.md``). PX4 starts headless in a new folder
under /tmp; the pymavlink client of ``corpora/tlog/record_px4.py`` (system 245, the onboard
link) flies: 2 s of position setpoints at 20 Hz, switch to OFFBOARD, arm, climb to 3 m, hold;
then

* a disarm request (MAV_CMD_COMPONENT_ARM_DISARM param1 0, not forced) in flight;
* an arm request while armed;
* four stops of the stream of 1.6 s each, started 37 ms later each time so that PX4's 10 Hz
  check pass meets them at different phases, the stream resuming after each;
* AUTO_LAND, and a disarm request as soon as the local position is within 0.3 m of the ground
  (before PX4's land detector says landed).

Written beside this script: ``px4_<release>_disarm_in_flight.ulg`` (PX4's own log, cut by
pyulog to the topics fuzzoff reads, as ``corpora/real/cut.py`` does) and
``px4_<release>_disarm_in_flight.onboard.tlog`` (the onboard link, trimmed by
``corpora/tlog/record_px4.py``'s ``trim``).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from pyulog import ULog

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tlog"))

import record_px4 as flightlib  # noqa: E402  (corpora/tlog/record_px4.py, a script beside)

from fuzzoff.formats.ulog.reader import LOADED_TOPICS  # noqa: E402

STOPS = 4
STOP_S = 1.6


def fly(flight: flightlib.Flight) -> None:
    flight.pump(2.0)
    flight.wait(lambda: flight.healthy, 120)
    flight.start_logs()
    flight.pump(1.0)
    hover = flight.position(0.0, 0.0, -3.0)
    flight.pump(2.0, hover)
    flight.command(176, 1, flightlib.OFFBOARD_MAIN)
    flight.pump(0.5, hover)
    flight.arm(hover)
    flight.wait(lambda: flight.z < -2.7, 30, hover)
    flight.pump(3.0, hover)
    flight.command(400, 0)  # disarm in flight: PX4 refuses it
    flight.pump(1.0, hover)
    flight.command(400, 1)  # arm while armed
    flight.pump(1.0, hover)
    for k in range(STOPS):
        flight.pump(2.0 + 0.037 * k, hover)
        flight.pump(STOP_S)  # no setpoint: PX4 declares the loss, runs its failsafe
        flight.pump(2.0, hover)  # back: PX4 returns to OFFBOARD by itself
    flight.command(176, 1, flightlib.AUTO_MAIN, flightlib.LAND_SUB)
    flight.wait(lambda: not flight.armed or flight.z > -0.3, 60)
    flight.pump(1.0)
    if flight.armed:
        flight.command(400, 0)  # near the ground, before the land detector says landed
        flight.pump(1.0)
    flight.pump(1.0)


def cut(source: Path, target: Path) -> None:
    log = ULog(str(source), message_name_filter_list=list(LOADED_TOPICS))
    log.write_ulog(str(target))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bundle", type=Path, default=flightlib.SHARED / "1.15.4")
    parser.add_argument("--instance", type=int, default=6)
    args = parser.parse_args()
    name = f"px4_{args.bundle.name.replace('.', '_').replace('-', '_')}_disarm_in_flight"
    work = Path(tempfile.mkdtemp(prefix=f"fuzzoff-gate-px4-{args.instance}-"))
    env = os.environ | {"PX4_INSTANCE": str(args.instance)}
    px4 = subprocess.Popen(
        [str(flightlib.SHARED / "run-px4.sh"), str(args.bundle), str(work / "px4")],
        env=env,
        stdout=(work / "px4.out").open("w"),
        stderr=subprocess.STDOUT,
    )
    flight = flightlib.Flight(args.instance, work, name)
    try:
        fly(flight)
    finally:
        flight.close()
        px4.send_signal(signal.SIGINT)
        px4.wait(timeout=30)
    kept, dropped = flightlib.trim(flight.paths[0], HERE / f"{name}.onboard.tlog")
    (ulog,) = sorted((work / "px4" / "log").rglob("*.ulg"))
    cut(ulog, HERE / f"{name}.ulg")
    print(f"{name}: {work}; onboard kept {kept}, dropped {dropped}; ulog {ulog}")


if __name__ == "__main__":
    main()
