"""What a disagreement between PX4 and the gate model is, before anyone reads it.

- ``signature``: a disagreement without its times, so that a second run or a simpler variant
  can be said to show *the same* disagreement;
- ``own_changes``: the modes and arming changes PX4 made by itself (no command of the client's
  and no offboard loss before them: a failure detector that disarmed a flipped vehicle, a
  land detector, a low battery). The gate model knows nothing of the vehicle's flight, so a
  disagreement after one is about the vehicle, not about the offboard gate;
- ``shape``: what PX4's gate can tell apart in a stream (commands and their order, setpoint
  kinds, frames and masks, the gaps of 0.2 s or more, the parameters): a live campaign sends
  one stream of each shape, since each costs seconds of real time;
- ``edge_note``: a keep-alive gap within one 10 Hz check period of the loss timeout, where
  PX4's outcome depends on the phase of its own check (gate.md#check-timing) and the model fixes it.
"""

from __future__ import annotations

import itertools
import re

from fuzzoff import events as ev
from fuzzoff.fuzz.scenario import Scenario
from fuzzoff.gate.params import default_params, loss_timeout
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.mavlink_ids import MAV_CMD_COMPONENT_ARM_DISARM
from fuzzoff.modes import nav_state_name
from fuzzoff.sitl.truth import Truth
from fuzzoff.sitl.verdict import CHECK_PERIOD_S, LOOP_S, MODE_SETTLE_S, Item

REQUEST_EFFECT_S = 1.0
"""A mode or arming change this soon after an accepted command of the client is its effect."""
TEXT_BEFORE_S = 0.5
QUIET_TEXTS = ("[tone_alarm]", "[logger]")


def signature(item: Item) -> tuple[str, str, str]:
    """What a disagreement is, without its times."""
    model = item.model.split(":")[0]
    px4 = "outside the window" if item.what == "loss time" else item.px4
    return (item.what, re.sub(r"[\d.]+ s", "", px4), re.sub(r"[\d.]+", "#", model))


@dataclass(frozen=True, slots=True)
class OwnChange:
    t: float
    what: str
    texts: tuple[str, ...]
    """PX4's own messages just before it (its ULog's logged messages)."""

    def describe(self) -> str:
        why = f" ({'; '.join(self.texts)})" if self.texts else ""
        return f"PX4 {self.what} by itself at {self.t:.3f} s{why}"


def own_changes(truth: Truth, since: float) -> list[OwnChange]:
    """The changes of mode or arming after ``since`` that no accepted command of the client
    and no change of PX4's loss flag explains."""
    accepted = [r.t for r in truth.requests if r.result == 0]
    flags = [t for t, _ in truth.loss_flag]
    out = []
    for prev, mode in itertools.pairwise(truth.modes):
        if mode.t < since:
            continue
        if any(0 <= mode.t - t <= REQUEST_EFFECT_S for t in accepted):
            continue
        if any(-LOOP_S <= mode.t - t <= MODE_SETTLE_S for t in flags):
            continue
        if prev.armed and not mode.armed:
            what = "disarmed"
        elif mode.armed and not prev.armed:
            what = "armed"
        else:
            what = f"went to {nav_state_name(mode.nav_state)}"
        texts = tuple(
            text.strip()
            for t, text in truth.texts
            if mode.t - TEXT_BEFORE_S <= t <= mode.t + LOOP_S and not text.startswith(QUIET_TEXTS)
        )
        out.append(OwnChange(mode.t, what, texts[:3]))
    return out


HEALTH_TEXT_S = 1.5
"""PX4 reports a failed health check when it finds it and refuses an arm while it stands: its
text may come a second or so before the refusal."""
HEALTH_WORDS = ("preflight fail",)
"""Which check failed; "Arming denied: Resolve system health failures first" alone is also
what PX4 says when it refuses an arm in OFFBOARD without a stream, the gate's own refusal."""
GATE_WORDS = ("offboard", "mode", "control signal")


def health_refusals(truth: Truth, since: float) -> list[OwnChange]:
    """Arms PX4 refused for its own health checks (an estimator that has not settled after a
    landing: "Preflight Fail: horizontal velocity unstable"), which the gate model does not
    model; not a refusal for the mode (OFFBOARD without a signal), which it does."""
    out = []
    for request in truth.requests:
        if request.t < since or request.command != MAV_CMD_COMPONENT_ARM_DISARM:
            continue
        if request.param1 != 1.0 or request.result in (0, None):
            continue
        texts = [
            text.strip()
            for t, text in truth.texts
            if request.t - HEALTH_TEXT_S <= t <= request.t + LOOP_S
            and not text.startswith(QUIET_TEXTS)
        ]
        low = " ".join(texts).lower()
        if any(w in low for w in HEALTH_WORDS) and not any(w in low for w in GATE_WORDS):
            out.append(OwnChange(request.t, "refused the arm", tuple(texts[:3])))
    return out


def shape(scenario: Scenario) -> tuple[object, ...]:
    """A stream at 0.1 s resolution, as far as PX4's offboard gate can tell it apart."""
    from fuzzoff.sitl.variants import label

    commands = tuple(
        (label(e), round(e.t, 1)) for e in scenario.events if isinstance(e, ev.Command)
    )
    setpoints = [e for e in scenario.events if isinstance(e, ev.MavlinkTarget)]
    kinds = sorted({(e.kind, getattr(e, "coordinate_frame", 0), e.type_mask) for e in setpoints})
    gaps = tuple(
        (round(a.t, 1), round(b.t - a.t, 1))
        for a, b in itertools.pairwise(setpoints)
        if b.t - a.t >= 0.2
    )
    span = (round(setpoints[0].t, 1), round(setpoints[-1].t, 1)) if setpoints else ()
    params = tuple(sorted((k, round(v, 2)) for k, v in scenario.params.items()))
    return (commands, tuple(kinds), gaps, span, params)


def edge_note(scenario: Scenario) -> str | None:
    timeout = loss_timeout(scenario.px4, default_params(scenario.px4) | dict(scenario.params))
    times = [e.t for e in scenario.events if isinstance(e, ev.MavlinkTarget)]
    near = [
        b - a
        for a, b in itertools.pairwise(times)
        if timeout - LOOP_S <= b - a <= timeout + CHECK_PERIOD_S + LOOP_S
    ]
    if not near:
        return None
    return (
        f"a keep-alive gap of {max(near):.3f} s is within one 10 Hz check period of the loss"
        f" timeout ({timeout:g} s): whether PX4 flags it depends on the phase of its check"
    )
