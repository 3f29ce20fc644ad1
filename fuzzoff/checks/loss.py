"""OFB103: the keep-alive stopped in offboard for longer than the loss timeout.

Driven by the gate model's ``failsafe`` transitions (gate.md#loss); where the gate did not see the
vehicle in offboard but the recording does (a MAVROS bag has no mode commands to model), the same
timeout is applied to the recorded mode so the loss is still reported. Where the recording shows
what the vehicle did next, the finding compares it with the model's action.

Times quoted: the model's loss as the gate dates it (PX4's own flag where the recording holds
it, else the window of PX4's 10 Hz check pass, gate.md#check-timing); the recorded change as the
recording shows it: the first status with the new mode, or, where the mode is sampled over a
link (1 Hz HEARTBEAT, ``/mavros/state``), between the last sample still in OFFBOARD and that one.
"""

from __future__ import annotations

from fuzzoff.checks._keepalive import (
    KEEPALIVE_EVENTS,
    TIME_EPSILON_S,
    keepalive_run,
    loss_timeout,
    px4_label,
)
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import NAV_STATE_OFFBOARD, Event, VehicleStatus, Where
from fuzzoff.gate import GateTransition
from fuzzoff.gate.compare import over_a_link
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name

RECORDED_ANSWER_WINDOW_S = 2.5
"""How long after the predicted failsafe a recorded mode change still counts as its answer
(PX4's HEARTBEAT is 1 Hz and the loss is evaluated at 10 Hz)."""


def _inner(message: str) -> str:
    """``offboard signal lost (why)`` -> ``why``."""
    _head, sep, rest = message.partition("(")
    return rest[:-1] if sep and rest.endswith(")") else message


@dataclass(frozen=True, slots=True)
class _Change:
    """A recorded change out of OFFBOARD: first sample with the new mode, the sample before."""

    t: float
    before: float | None
    nav: int | None
    sampled: bool
    """The mode reached the recording over a link at 1 Hz: the change lies between the two."""

    def text(self, brief: bool = False) -> str:
        """The change as the finding says it; ``brief`` for the one-line view (a range)."""
        mode = nav_state_name(self.nav)
        if self.sampled and self.before is not None:
            if brief:
                return f"{mode} {self.before:.2f}-{self.t:.2f} s (1 Hz status)"
            return f"{mode} between {self.before:.2f} and {self.t:.2f} s (mode sampled at 1 Hz)"
        return f"{mode} at {self.t:.2f} s"


def loss_when(lost: GateTransition) -> str:
    """The time of the gate's ``signal_lost``: a window, or where the recording shows it."""
    if lost.t_earliest is not None:
        return (
            f"between {lost.t_earliest:.2f} and {lost.t:.2f} s (its 10 Hz check pass, at a phase "
            "the recording does not show)"
        )
    if lost.seen_in is not None:
        return f"at {lost.t:.2f} s ({lost.seen_in})"
    return f"at {lost.t:.2f} s"


@dataclass(slots=True)
class _Pending:
    t: float
    message: str
    where: Where
    last_keepalive: float | None
    short: str = ""


class OffboardLoss(Check):
    codes = ("OFB103",)
    wants = (*KEEPALIVE_EVENTS, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.last: float | None = None
        self.last_where = Where("keep-alive")
        self.last_flying = False
        self.pending: _Pending | None = None
        self.lost: GateTransition | None = None
        """The gate's latest ``signal_lost`` (its message says why: silence, an old stamp...)."""
        self.reported_until: float = -1.0
        """Keep-alive time up to which a loss has been reported (one finding per gap)."""
        self.sample_t: float | None = None
        """The previous recorded status's time."""
        self.left: _Change | None = None
        """The latest recorded change out of OFFBOARD (None while the recording shows it)."""
        self.mode_seen = False
        """A recorded status has named a mode."""

    def on_event(self, event: Event) -> None:
        if self.pending is not None and event.t - self.pending.t > RECORDED_ANSWER_WINDOW_S:
            self._flush(None)
        state = self.ctx.state
        if event is state.keepalive:  # first: nearly every message is one
            if self.last_flying:
                self._gap_from_recording(event.t)
            self.last, self.last_where = event.t, event.where
            gate = self.ctx.gate
            gate_models_it = gate.armed and gate.user_intention == NAV_STATE_OFFBOARD
            # The gate is the authority where it models offboard; the recorded mode otherwise.
            self.last_flying = self.ctx.flying and not gate_models_it
        elif isinstance(event, GateTransition):
            if event.what == "signal_lost":
                self.lost = event
            elif event.what == "failsafe":
                self._from_gate(event)
        elif isinstance(event, VehicleStatus):
            self._sample(event)
            if self.pending is not None and event.nav_state is not None and not event.in_offboard:
                self._flush(self.left)
            if self.last_flying and not self.ctx.flying:
                self._gap_from_recording(event.t)  # only the silence spent in OFFBOARD counts
                self.last_flying = False

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: no answer pending and no gap (from ``last`` into the run, or inside it
        while the recorded mode is the authority) as long as the loss timeout, the only gap
        ``_gap_from_recording`` reports: then only ``last`` and ``last_flying`` move, to
        what the run's newest keep-alive leaves (every keep-alive sets the same
        ``last_flying``: the state and the gate model do not change within a run)."""
        if self.pending is not None:
            self.replay(batch)  # any message may close the recorded-answer window
            return
        if not batch.keepalives():
            return  # without an answer pending only keep-alives matter
        run = keepalive_run(batch)
        gate = self.ctx.gate
        gate_models_it = gate.armed and gate.user_intention == NAV_STATE_OFFBOARD
        flying = self.ctx.flying and not gate_models_it
        timeout = loss_timeout(self.ctx)
        last = self.last
        if (self.last_flying and last is not None and not run.times[0] - last < timeout) or (
            flying and not run.widest < timeout
        ):
            self.replay(batch)
            return
        self.last, self.last_where = run.times[-1], run.events[-1].where
        self.last_flying = flying

    def _sample(self, status: VehicleStatus) -> None:
        """Keep where the recording shows the vehicle leaving OFFBOARD."""
        if status.nav_state is not None:
            self.mode_seen = True
            if status.in_offboard:
                self.left = None
            elif self.left is None:
                self.left = _Change(status.t, self.sample_t, status.nav_state, over_a_link(status))
        self.sample_t = status.t

    def _from_gate(self, tr: GateTransition) -> None:
        self._flush(None)  # a loss still waiting for the recorded answer is reported first
        timeout = loss_timeout(self.ctx)
        if self.last is None:
            stopped = "no keep-alive"
        elif self.lost is not None and self.lost.t - self.last < timeout - TIME_EPSILON_S:
            # lost sooner than a timeout after the newest keep-alive: not silence but, e.g., an
            # old timestamp (gate.md#signal) or a declaration without a flag
            why = self.lost.reason or _inner(self.lost.message)
            stopped = f"the keep-alive kept arriving but PX4 no longer counts it ({why})"
        else:
            stopped = f"the keep-alive stopped at {self.last:.2f} s"
        action = tr.action or "its failsafe"
        when = loss_when(self.lost) if self.lost is not None else f"by {tr.t:.2f} s"
        message = (
            f"{stopped} while in OFFBOARD; {px4_label(self.ctx)} declares the offboard signal lost "
            f"{when} and runs {action} (loss timeout {timeout:.2f} s)"
        )
        if tr.reason:
            message += f" ({tr.reason})"
        counted = not stopped.startswith("the keep-alive kept arriving")
        brief = stopped.removeprefix("the ") if counted else "keep-alive no longer counted"
        at = f"at {tr.t:.2f} s"
        if tr.t_earliest is not None:  # PX4's check window, its phase not recorded
            at = f"{tr.t_earliest:.2f}-{tr.t:.2f} s"
        short = f"{brief}: {action} {at}"
        self.reported_until = self.last if self.last is not None else tr.t
        self.pending = _Pending(tr.t, message, self.last_where, self.last, short)
        left = self.left
        if not self.ctx.state.mode_recorded:
            self._flush(None)
        elif left is not None and tr.t - left.t <= RECORDED_ANSWER_WINDOW_S:
            self._flush(left)  # the recording showed the change first (PX4's own timing)

    def _gap_from_recording(self, now: float) -> None:
        """A loss the gate did not model, judged on the recorded mode with the same timeout."""
        if self.last is None or not self.last_flying or self.last <= self.reported_until:
            return
        timeout = loss_timeout(self.ctx)
        if now - self.last < timeout:
            return
        self.reported_until = self.last
        act = self.ctx.gate.params.get("COM_OBL_RC_ACT", 0.0)
        message = (
            f"the keep-alive stopped at {self.last:.2f} s for {now - self.last:.2f} s while the "
            f"recording shows OFFBOARD; {px4_label(self.ctx)} loses the offboard signal after "
            f"{timeout:.2f} s and runs the COM_OBL_RC_ACT = {act:g} failsafe"
        )
        short = (
            f"keep-alive stopped for {now - self.last:.2f} s in OFFBOARD; "
            f"{px4_label(self.ctx)} runs its loss failsafe after {timeout:.2f} s"
        )
        self.ctx.report(
            "OFB103", message, self.last + timeout, self.last_where, end=now, short=short
        )

    def _flush(self, answer: _Change | None) -> None:
        pending, self.pending = self.pending, None
        if pending is None:
            return
        message, short = pending.message, pending.short
        if answer is not None:
            message += f"; recorded: {answer.text()}"
            short += f"; recorded: {answer.text(brief=True)}"
        elif self.ctx.state.mode_recorded:
            recorded = self._recorded_now()
            message += f"; recorded: {recorded}"
            short += f"; recorded: {recorded}"
        else:
            message += " (the recording has no mode to compare)"
        self.ctx.report("OFB103", message, pending.t, pending.where, short=short)

    def _recorded_now(self) -> str:
        """The recorded mode while no change out of OFFBOARD answered the loss: still the
        same mode, or none yet (no status before it named one), or a switch away
        accepted by its ack whose mode no status has named yet."""
        nav = self.ctx.state.nav_state
        if nav is not None:
            return f"still {nav_state_name(nav)}"
        if not self.mode_seen:
            return "no mode yet (no status names one before it)"
        return "a switch away from OFFBOARD accepted, its mode not yet in a status"

    def finish(self, t_end: float) -> None:
        self._flush(None)
        if self.last is not None and self.last_flying and self.last > self.reported_until:
            timeout = loss_timeout(self.ctx)
            if t_end - self.last >= timeout:
                self._gap_from_recording(t_end)
