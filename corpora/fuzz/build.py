"""Rebuild the reproducers of the known problems (fuzzoff/fuzz/known.py) from seeded campaigns.

Run as ``.venv/bin/python corpora/fuzz/build.py``. Each entry is a campaign (property, profile,
transport, seed) that finds the problem; the shrunk counterexample is saved here as a recording
plus ``NAME.expected.json`` (what ``fuzzoff lint`` says about it, the property and the problem).
``make test`` replays the findings; ``fuzzoff replay NAME.expected.json`` re-checks the property
(exit 0 once the problem is fixed: then drop the entry here and in known.py, and mark the
reproducer ``"fixed"`` to keep it as a regression case; those are left as they are).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

from fuzzoff.fuzz.campaign import CampaignConfig, run_campaign
from fuzzoff.fuzz.known import KNOWN
from fuzzoff.fuzz.reproducers import save
from fuzzoff.fuzz.scenario import TransportName

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True, slots=True)
class Entry:
    pattern: str
    """The known.py key the reproducer shows."""
    prop: str
    px4: str | None
    transport: TransportName | None
    seed: int
    vehicle: str | None = "mc"


_MAV = r"silent hazard \((mavlink|mavros), "
ENTRIES = (
    Entry(
        _MAV + r"PX4 1\.11\): setpoint_dropped .*GLOBAL_INT handler \(unverified\)",
        "explained",
        "1.11",
        "mavlink",
        1,
    ),
)


def build(entry: Entry) -> Path:
    others = tuple(k for k in KNOWN if k != entry.pattern)
    config = CampaignConfig(
        px4=entry.px4,
        vehicle=entry.vehicle,
        transport=entry.transport,
        examples=2000,
        seed=entry.seed,
        properties=(entry.prop,),
        known=others,
        shrink_s=60.0,
    )
    (result,) = run_campaign(config).results
    if not result.failed or result.counterexample is None:
        raise SystemExit(f"{entry}: the campaign found nothing")
    if not any(re.search(entry.pattern, p) for p in result.problems):
        raise SystemExit(f"{entry}: found something else: {result.problems}")
    return save(entry.prop, result.counterexample, result.problems, HERE)


def _stale() -> list[Path]:
    """The files of the reproducers not kept as regression cases (``"fixed"``): rebuilt."""
    out = []
    for spec_path in HERE.glob("*.expected.json"):
        spec = json.loads(spec_path.read_text())
        if "fixed" in spec:
            continue
        out.append(spec_path)
        out += [HERE / spec[key] for key in ("recording", "stream") if key in spec]
    return out


def main() -> None:
    for old in _stale():
        old.unlink(missing_ok=True)
    for entry in ENTRIES:
        print(build(entry).relative_to(HERE.parent.parent))


if __name__ == "__main__":
    main()
