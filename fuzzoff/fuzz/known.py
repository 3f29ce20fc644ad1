"""Known problems the campaigns found and that are not fixed yet (each with a reproducer).

Campaigns leave these out so that the search goes on for new ones (a user's campaign must not
fail on fuzzoff's own problems), and count them; ``fuzzoff fuzz --include-known`` fails on them
(for fuzzoff's developers), and tests/test_fuzz_reproducers.py checks that each reproducer
still fails. Each entry: a regular expression matched against a property's problem text -> what
it is. Remove an entry when its reproducer under ``corpora/fuzz/`` replays as fixed
(``fuzzoff replay`` exits 0), and mark the reproducer ``"fixed"``.
"""

from __future__ import annotations

_MAV = r"silent hazard \((mavlink|mavros), "

KNOWN: dict[str, str] = {
    _MAV + r"PX4 1\.11\): setpoint_dropped .*GLOBAL_INT handler \(unverified\)": (
        "PX4 1.11's SET_POSITION_TARGET_GLOBAL_INT handler is unverified "
        "(docs/gate.md#unverified): the gate model takes it as a keep-alive without a setpoint, "
        "OFB609 says so as a warning"
    ),
}
