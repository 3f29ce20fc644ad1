"""The gate model's output: a timeline of transitions, each an event the checks also see."""

from __future__ import annotations

from typing import ClassVar, Literal

from fuzzoff.events import Event, Origin, event_type

TransitionKind = Literal[
    "signal_available",
    "signal_lost",
    "request_accepted",
    "request_rejected",
    "arm_accepted",
    "arm_rejected",
    "disarm_rejected",
    "failsafe",
    "offboard_resumed",
    "mode",
    "controller",
    "setpoint_dropped",
    "disarmed",
    "disagreement",
    "undecided",
]
"""``mode``: a mode change that is not an offboard request (another mode requested, or the
model re-synchronised to the recording); ``disagreement``: the recording shows something the
model did not predict (recorded mode or ack vs the model's), see ``recorded_nav_state``;
``undecided``: a request whose outcome depends on the arming state, which the recording does
not show (``reason`` names both outcomes)."""


@event_type
class GateTransition(Event):
    """One change the gate model predicts, at ``t``, caused by ``cause`` (None for a timeout).

    ``spec`` numbers the part of PX4's behaviour the transition implements, which
    ``gate.sections`` maps to a section of docs/gate.md (``5.1`` -> gate.md#loss);
    ``unverified`` marks behaviour not verified on PX4 (gate.md#unverified).
    """

    kind: ClassVar[str] = "gate"

    what: TransitionKind
    message: str
    spec: str
    cause: Event | None = None
    nav_state: int | None = None
    """The effective nav_state after the transition, where it changed or is known."""
    action: str | None = None
    """Failsafe action name (e.g. ``POSCTL``, ``AUTO_RTL``) for ``failsafe`` transitions."""
    reason: str | None = None
    """Why a request was rejected or a setpoint dropped, in PX4's terms."""
    unverified: bool = False
    origin: Origin = "model"
    armed: bool | None = None
    """The model's arming state after the transition."""
    recorded_nav_state: int | None = None
    """``disagreement``: the nav_state the recording shows (None for an ack disagreement)."""
    t_earliest: float | None = None
    """A loss whose time is a window (PX4's 10 Hz check pass at a phase the recording does not
    show): ``t`` is its latest time, this its earliest. None: ``t`` is the time."""
    seen_in: str | None = None
    """Where the recording shows PX4 doing it (e.g. ``PX4's failsafe_flags``), when the model
    took the time from there."""
