"""Known problems the campaigns found and that are not fixed yet (each with a reproducer).

CI campaigns (tests/test_fuzz_campaigns.py) leave these out so the search goes on for new ones;
``fuzzoff fuzz --known`` does the same. Each entry: a regular expression matched against a
property's problem text -> what it is. Remove an entry when its reproducer under
``corpora/fuzz/`` replays as fixed (``fuzzoff replay`` exits 0).
"""

from __future__ import annotations

_MAV = r"silent hazard \((mavlink|mavros), "

KNOWN: dict[str, str] = {
    _MAV + r".*controller .*no TrajectorySetpoint since": (
        "PX4 forwards MAVLink setpoints only in OFFBOARD, so after the switch the vehicle holds "
        "until the next one arrives; no rule reports a long hold after the switch for a "
        "MAVLink stream (OFB303 covers ROS 2 only)"
    ),
    _MAV + r"PX4 (legacy|1\.11)\): setpoint_dropped": (
        "legacy/1.11 MAVLink receiver drops (GLOBAL_INT not handled, non-finite fields, FORCE "
        "bit, takeoff bit as loiter): no legacy rule covers them (OFB6xx apply from 1.13)"
    ),
    r"setpoint_dropped .*no position, velocity or acceleration": (
        "SET_POSITION_TARGET_LOCAL_NED in MAV_FRAME_BODY_NED with only position set: the "
        "receiver drops it (gate spec 6.2, D17) but OFB601/OFB602 are silent"
    ),
}
