"""What the gate model predicts that the stream did not intend, and which rules explain it.

A *hazard* is a ``GateTransition`` of one of these kinds (the docs/gate.md section in brackets):

* ``request_rejected`` / ``arm_rejected``: the stream asked for OFFBOARD or to arm in it (4.1, 4.2);
* ``failsafe``: the loss failsafe ran (5), and ``disarmed`` by it (not by a disarm command);
  not a failsafe the model ends within one Commander iteration (a tie at the threshold, which
  changes nothing; the invariants check the model's timeline itself);
* ``setpoint_dropped``: the MAVLink receiver dropped or ignored a setpoint (6);
* ``controller`` with a reason that lasts ``HOLD_S`` or more while armed: another controller
  runs than the setpoint asked for (the failsafe setpoint, the 200 ms reuse; 8-10). Shorter
  ones are the moment between a keep-alive and its setpoint, which PX4 also sees.

``EXPLAINED_BY`` names the rules whose findings explain each kind: rules about the very outcome
(OFB201, OFB103, OFB6xx...) and about its causes (a gap, an empty control mode, a dropped
keep-alive...). Each rule says which kinds it explains in its page (``rules/CODE.toml``,
``explains`` and ``reports``): a new rule that explains an outcome needs no change here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from fuzzoff.catalog import HAZARD_KINDS, CatalogError, Rule, load_catalog
from fuzzoff.events import Command
from fuzzoff.gate import GateTransition
from fuzzoff.gate.sections import cite
from fuzzoff.lean_dataclass import dataclass

HOLD_S = 0.2
"""A controller hazard must last this long (PX4 1.16's last-valid reuse window)."""
WAIT_S = 0.55
"""The hold before the first setpoint after the switch must last longer than the period of the
slowest stream the docs allow (2 Hz, plus 10 % jitter): a stream's own rate is intended."""
NO_SETPOINT_YET = "no TrajectorySetpoint since"


def explained_by(
    catalog: Mapping[str, Rule],
) -> tuple[dict[str, frozenset[str]], dict[str, str]]:
    """Each kind's explaining rules and the rule that reports it, from the rules' pages."""
    explained: dict[str, set[str]] = {kind: set() for kind in HAZARD_KINDS}
    outcome: dict[str, str] = {}
    for rule in catalog.values():
        for kind in rule.explains:
            explained[kind].add(rule.code)
        for kind in rule.reports:
            if kind in outcome:
                raise CatalogError(f"{rule.code}: {kind} is reported by {outcome[kind]} already")
            outcome[kind] = rule.code
    return {kind: frozenset(codes) for kind, codes in explained.items()}, outcome


EXPLAINED_BY, OUTCOME_RULE = explained_by(load_catalog())
"""``EXPLAINED_BY``: the rules whose findings explain each kind (``explains`` in their pages).
``OUTCOME_RULE``: the rule that reports the outcome itself (``reports``): when the recording
cannot show it (OFB002 says so), a warning of an explaining rule is enough (e.g. OFB102 before
a rejected switch in a recording without acks)."""


WHILE_ARMED = frozenset({"failsafe", "disarmed", "controller"})
"""Kinds that are hazards only in flight: a disarmed vehicle holds nothing and flies nowhere."""


def _armed_before(tr: GateTransition, transitions: Sequence[GateTransition]) -> bool:
    """Was the model armed when ``tr`` happened (a loss action may disarm in ``tr`` itself)?"""
    if tr.what == "disarmed":
        return True
    return bool(tr.armed)


BLIP_S = 0.0105
"""A failsafe the model ends within one Commander iteration (the keep-alive that ends the loss
arrives at the loss time itself: a tie at the threshold) changes nothing the vehicle does."""


def _blip(tr: GateTransition, transitions: Sequence[GateTransition]) -> bool:
    idx = next(i for i, x in enumerate(transitions) if x is tr)
    for x in transitions[idx + 1 :]:
        if x.what == "offboard_resumed":
            return abs(x.t - tr.t) <= BLIP_S
        if x.what == "failsafe" or x.t > tr.t + BLIP_S:
            return False
    return False


def _undone_earlier(tr: GateTransition, transitions: Sequence[GateTransition]) -> bool:
    """A transition listed after ``tr`` but timed before it (the model bug in fuzz.known)."""
    idx = next(i for i, x in enumerate(transitions) if x is tr)
    return any(x.t < tr.t - 1e-9 for x in transitions[idx + 1 : idx + 4])


@dataclass(frozen=True, slots=True)
class Hazard:
    t: float
    kind: str
    message: str
    spec: str
    end: float
    nav_state: int | None = None
    """The mode the vehicle is in after it (a failsafe's action), where the model says."""

    def describe(self) -> str:
        see = cite(self.spec)
        return f"{self.kind} at {self.t:.3f} s ({self.message}" + (f"; {see})" if see else ")")


def hazards(transitions: Sequence[GateTransition], t_end: float) -> list[Hazard]:
    """The unintended outcomes among a vehicle's transitions, in time order."""
    out: list[Hazard] = []
    controllers = [tr for tr in transitions if tr.what == "controller"]
    for tr in transitions:
        what = tr.what
        if what == "disarmed" and isinstance(tr.cause, Command):
            continue
        if what == "controller":
            if not tr.reason:
                continue
            idx = next(i for i, c in enumerate(controllers) if c is tr)
            end = controllers[idx + 1].t if idx + 1 < len(controllers) else t_end
            # Counted from when the vehicle is armed while it runs (arming after the switch
            # changes no controller): a hold on the ground is no hazard.
            armed_at = (
                tr.t
                if tr.armed
                else next((x.t for x in transitions if tr.t <= x.t < end and x.armed), None)
            )
            if armed_at is None:
                continue
            # ...and only while it stays armed: a disarm ends what the controller flies
            end = next((x.t for x in transitions if armed_at < x.t < end and x.armed is False), end)
            hold = WAIT_S if tr.reason.startswith(NO_SETPOINT_YET) else HOLD_S
            if end - armed_at < hold:
                continue
            out.append(Hazard(tr.t, what, tr.message, tr.spec, end))
        elif (what in WHILE_ARMED and not _armed_before(tr, transitions)) or (
            what == "failsafe" and _blip(tr, transitions)
        ):
            continue
        elif what in EXPLAINED_BY:
            message = tr.message
            if _undone_earlier(tr, transitions):
                message += " [undone by a transition before it: timeline out of order]"
            out.append(Hazard(tr.t, what, message, tr.spec, tr.t, tr.nav_state))
    return out
