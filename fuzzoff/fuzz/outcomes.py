"""What a perturbation changes in what PX4 does, in a user's words: "PX4 1.15 runs POSCTL at
7.2 s (offboard loss)". ``fuzz --from`` reports the smallest perturbation that changes the gate
model's outcome; this says which outcome flips.

A hazard of the perturbed stream is the same outcome as one of the recording's own when it has
the same kind and comes within the time the perturbation itself moves the stream (a stall of
0.5 s delays a loss the recording already had by 0.5 s), plus the 0.1 s the outcome is
compared at. The rest are new: one of the same kind and mode as a recording's hazard left
unmatched is that outcome at another time ("at 8.7 s, not at 9.1 s"); the recording's hazards
still unmatched are gone ("no longer: ...").
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from fuzzoff.fuzz.hazards import Hazard, hazards
from fuzzoff.fuzz.scenario import Scenario, run
from fuzzoff.modes import nav_state_name
from fuzzoff.releases import PX4Profile
from fuzzoff.timeline import Timeline

_TIMING = re.compile(r" (?:between [\d.]+ and [\d.]+ s|at [\d.]+ s \([^)]*\))")
"""The time words of a gate failsafe message (its window, or where the recording dated it)."""


def hazards_of(scenario: Scenario) -> list[Hazard]:
    """Every vehicle's hazards in the scenario, in time order."""
    timelines: dict[str, Timeline] = {}
    run(scenario, timelines=timelines)
    found = [h for tl in timelines.values() for h in hazards(tl.transitions, scenario.duration)]
    return sorted(found, key=lambda h: h.t)


def changes(
    px4: PX4Profile, before: Sequence[Hazard], after: Sequence[Hazard], moved_s: float
) -> list[str]:
    """What PX4 does after the perturbation and did not before, then what it no longer does."""
    unmatched = list(before)
    new = []
    for h in after:
        same = next(
            (b for b in unmatched if b.kind == h.kind and abs(b.t - h.t) <= moved_s + 0.1),
            None,
        )
        if same is None:
            new.append(h)
        else:
            unmatched.remove(same)
    out = []
    for h in new:
        moved = next(
            (b for b in unmatched if b.kind == h.kind and b.nav_state == h.nav_state), None
        )
        if moved is None:
            out.append(describe(px4, h))
        else:  # the same outcome at another time: a loss 0.4 s earlier
            unmatched.remove(moved)
            out.append(f"{describe(px4, h)}, not at {moved.t:.1f} s")
    return out + [f"no longer: {describe(px4, h)}" for h in unmatched]


def describe(px4: PX4Profile, h: Hazard) -> str:
    """One hazard as what PX4 does: "PX4 1.15 runs POSCTL at 7.2 s (offboard loss)"."""
    # "offboard loss between 5.81 and 5.91 s: POSCTL": the cause, not the gate's timing words
    cause = _TIMING.sub("", h.message.split(":", 1)[0])
    if h.kind == "failsafe":
        return f"PX4 {px4} runs {nav_state_name(h.nav_state)} at {h.t:.1f} s ({cause})"
    if h.kind == "disarmed":
        return f"PX4 {px4} disarms at {h.t:.1f} s ({cause})"
    if h.kind == "request_rejected":
        return f"PX4 {px4} rejects the switch to OFFBOARD at {h.t:.1f} s"
    if h.kind == "arm_rejected":
        return f"PX4 {px4} rejects the arming at {h.t:.1f} s"
    if h.kind == "setpoint_dropped":
        return f"PX4 {px4} drops a setpoint at {h.t:.1f} s ({h.message})"
    return f"PX4 {px4} runs another controller than the setpoint asks at {h.t:.1f} s ({h.message})"
