"""Known problems the campaigns found and that are not fixed yet (each with a reproducer).

CI campaigns (tests/test_fuzz_campaigns.py) leave these out so the search goes on for new ones;
``fuzzoff fuzz --known`` does the same. Each entry: a regular expression matched against a
property's problem text -> what it is. Remove an entry when its reproducer under
``corpora/fuzz/`` replays as fixed (``fuzzoff replay`` exits 0).
"""

from __future__ import annotations

_MAV = r"silent hazard \((mavlink|mavros), "

KNOWN: dict[str, str] = {
    _MAV + r"PX4 1\.11\): setpoint_dropped .*GLOBAL_INT handler \(unverified\)": (
        "PX4 1.11's SET_POSITION_TARGET_GLOBAL_INT handler is unverified (gate spec 6.3): the "
        "gate model takes it as a keep-alive without a setpoint, OFB609 says so as a warning"
    ),
}
