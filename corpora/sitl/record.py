"""Record the real-PX4 corpus: scenario programs flown on the bundled PX4 SITL releases.

Run ``.venv/bin/python corpora/sitl/record.py --release 1.16.2 --instance 0 [SCENARIO...]``
(when none is named: all on 1.16.2 and 1.18.0-alpha1, the release-dependent ones elsewhere).
Each run boots a fresh PX4 (``fuzzoff.sitl.session``), flies the program through pymavlink, and
leaves beside this file:

- ``NAME-RELEASE.tlog``: both directions of the offboard link as the client saw them, stamped
  on PX4's clock (``fuzzoff.sitl.recorder``);
- ``NAME-RELEASE.ulg``: PX4's own log, cut to the topics fuzzoff reads (``fuzzoff.sitl.trim``);
- an entry in ``runs.json``: the steps with PX4's time and PX4's answer, the parameters set
  (and those set at boot, ``boot_params``).

The expected findings are written separately (``expected.py``), from what the recordings hold.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from fuzzoff.sitl import airframes, bundle
from fuzzoff.sitl.link import LinkError
from fuzzoff.sitl.scenarios import SCENARIOS, scenarios_for, why_not_run
from fuzzoff.sitl.session import Session
from fuzzoff.sitl.trim import trim

HERE = Path(__file__).resolve().parent
RUNS = HERE / "runs.json"
THIN_S = 0.1


def record(release: str, instance: int, name: str) -> dict[str, object]:
    scenario = SCENARIOS[name]
    build = bundle.find_build(release, None)
    env = airframes.boot_env(build, scenario.vehicle)
    stem = f"{name}-{build.release}"
    tlog = HERE / f"{stem}.tlog"
    session = Session(build, instance, env=env)
    with session:
        result = session.run(
            name,
            scenario.program,
            tlog,
            manual=scenario.manual,
            params=scenario.params_for(build.release),
        )
        session.finish(result)
    if result.ulog is None:
        raise LinkError(f"{stem}: PX4 wrote no ULog")
    # the other vehicles' runs are longer (a VTOL's climb, transition and cruise): thin PX4's
    # fastest topics to 10 Hz to keep the ULog under 1 MB
    trim(result.ulog, HERE / f"{stem}.ulg", None if scenario.vehicle == "quad" else THIN_S)
    session.px4.cleanup()
    return {
        "recording": stem,
        "scenario": name,
        "release": build.release,
        "vehicle": scenario.vehicle,
        "ready_s": round(session.ready_s, 1),
        "error": result.error,
        "params": result.params,
        **(
            {"boot_params": boot}
            if (boot := airframes.airframe_for(scenario.vehicle).boot_params)
            else {}
        ),
        "steps": [
            {"px4_t": round(s.px4_t, 3), "what": s.what, "result": s.result} for s in result.steps
        ],
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--release", required=True)
    parser.add_argument("--instance", type=int, default=0)
    parser.add_argument("scenarios", nargs="*")
    args = parser.parse_args(argv)
    runs = json.loads(RUNS.read_text()) if RUNS.exists() else {}
    for name in args.scenarios or scenarios_for(args.release):
        reason = why_not_run(bundle.find_build(args.release, None).release, name)
        if reason is not None:
            print(f"{name} on {args.release}: not recorded: {reason}", file=sys.stderr)
            continue
        try:
            entry = record(args.release, args.instance, name)
        except (LinkError, bundle.BundleError) as exc:
            print(f"{name} on {args.release}: {exc}", file=sys.stderr)
            continue
        runs = json.loads(RUNS.read_text()) if RUNS.exists() else {}
        runs[str(entry["recording"])] = entry
        RUNS.write_text(json.dumps(dict(sorted(runs.items())), indent=1) + "\n")
        print(
            f"{entry['recording']}: {entry['steps']}"
            + (f" ERROR {entry['error']}" if entry["error"] else "")
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
