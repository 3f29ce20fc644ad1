"""Record real MAVSDK flying its offboard example on a PX4 SITL bundle, through the recording
proxy (``fuzzoff.sitl.proxy``), with PX4's ULog beside it.

    .venv/bin/python corpora/sitl/record_mavsdk.py --release 1.16.2 --python /tmp/mavsdk4/bin/python

``--python`` is the interpreter of a virtual environment with ``mavsdk`` installed
(``pip install 'mavsdk>=4,<5'``, or ``'mavsdk>=3,<4'`` for the gRPC package with its
``mavsdk_server``); the program is ``mavsdk_offboard.py`` beside this file (MAVSDK's offboard
example), or with ``--program actuator`` ``mavsdk_actuator.py`` (``set_actuator_control`` in
offboard, 4.x only). Before
MAVSDK connects, a short pymavlink session asks PX4 for its busy telemetry once a second (as
the scenario runs do), turns the logger on and waits until PX4 is ready to arm; the tlog then
holds the whole MAVSDK exchange.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from pyulog import ULog

from fuzzoff.formats.ulog.reader import LOADED_TOPICS
from fuzzoff.sitl import bundle
from fuzzoff.sitl.link import Link
from fuzzoff.sitl.proxy import RecordingProxy

HERE = Path(__file__).resolve().parent
CLIENT_PORT = 14640
"""Where the proxy hands PX4's stream to MAVSDK (+ instance)."""

PROGRAMS = {
    "offboard": ("mavsdk_offboard.py", "cpp/examples/offboard sequence"),
    "actuator": ("mavsdk_actuator.py", "offboard velocity, then set_actuator_control"),
}
"""``--program`` -> (the program beside this file, what it flies)."""


LEFT_OUT = frozenset({"vehicle_local_position"})
"""Topics fuzzoff reads that the kept runs leave out: the position at PX4's 100+ Hz would take
a run's ULog past 1 MB, and the runs recorded before the readers took it have none."""


def cut(source: Path, target: Path) -> Path:
    """PX4's log cut to the topics fuzzoff reads but ``LEFT_OUT`` (``fuzzoff.sitl.trim``'s
    way: pyulog reads them and writes them back, header, parameters and texts kept)."""
    log = ULog(str(source), message_name_filter_list=sorted(set(LOADED_TOPICS) - LEFT_OUT))
    log.write_ulog(str(target))
    return target


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--release", required=True)
    parser.add_argument("--instance", type=int, default=0)
    parser.add_argument("--python", required=True, help="a Python with mavsdk installed")
    parser.add_argument("--program", choices=sorted(PROGRAMS), default="offboard")
    args = parser.parse_args(argv)
    program, what = PROGRAMS[args.program]
    version = subprocess.run(
        [args.python, "-c", "import importlib.metadata as m; print(m.version('mavsdk'))"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    build = bundle.find_build(args.release, None)
    stem = f"mavsdk{version.split('.')[0]}_{args.program}-{build.release}"
    px4 = bundle.start(build, args.instance)
    try:
        link = Link(f"udpin:127.0.0.1:{px4.send_port}")
        try:
            link.connect(30)
            px4.command("logger", "on")
            link.quiet_telemetry()
            # MAVSDK's health_all_ok does not cover PX4 1.15's late attitude check: started
            # before PX4 passes its pre-arm checks, the example's arm() is denied there.
            link.wait_ready(90)
        finally:
            link.close()
        client = CLIENT_PORT + args.instance
        with RecordingProxy(px4.listen_port, px4.send_port, client, HERE / f"{stem}.tlog"):
            done = subprocess.run(
                [args.python, str(HERE / program), f"udpin://127.0.0.1:{client}"],
                timeout=300,
                capture_output=True,
                text=True,
            )
        print(done.stdout[-2000:], done.stderr[-2000:], sep="\n")
    finally:
        px4.stop()
    if px4.ulog is not None:
        cut(px4.ulog, HERE / f"{stem}.ulg")
    px4.cleanup()
    runs_path = HERE / "runs.json"
    runs = json.loads(runs_path.read_text()) if runs_path.exists() else {}
    runs[stem] = {
        "recording": stem,
        "scenario": f"mavsdk_{args.program}",
        "release": build.release,
        "client": f"mavsdk {version} (PyPI), {what}",
        "exit_status": done.returncode,
        "params": {},
    }
    runs_path.write_text(json.dumps(dict(sorted(runs.items())), indent=1) + "\n")
    return done.returncode


if __name__ == "__main__":
    sys.exit(main())
