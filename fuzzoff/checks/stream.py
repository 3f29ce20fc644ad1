"""OFB101, OFB102, OFB105: the keep-alive stream's rate and its run-up to an offboard request.

Seed 000 "Опис": a > 2 Hz proof of life, running for a second before an offboard request. The
messages say both what the docs require and what the profile's PX4 does (gate.md#signal,
#before-switch, #docs-vs-code),
and the severity is what PX4 does (rules.md): a gap PX4 takes for a loss is an error, one of
80 % of the loss timeout or more a warning, a shorter one (the docs' 2 Hz only) info.
"""

from __future__ import annotations

import math
from bisect import bisect_left
from collections import Counter
from functools import cache

from fuzzoff.checks._keepalive import (
    KEEPALIVE_EVENTS,
    PROOF_SLACK_S,
    RECEIVED_NOTE,
    RecordedSwitches,
    as_received,
    keepalive_run,
    loss_timeout,
    mode_note,
    proven_gap,
    px4_label,
)
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.checks.ignored_messages import IGNORED, ignores, message_name
from fuzzoff.events import (
    Command,
    CommandAck,
    Dropout,
    Event,
    VehicleStatus,
    Where,
)
from fuzzoff.findings import Severity
from fuzzoff.gate import GateTransition
from fuzzoff.gate.commander import SAME_ITERATION_S
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.state import DOUBLE_ACK_WINDOW_S

NEAR_LOSS_FRACTION = 0.8
"""A keep-alive gap of this share of the loss timeout or more is a warning (rules.md): PX4
keeps the signal, but only just."""

IN_OFFBOARD = "in OFFBOARD"
ACROSS_SWITCH = "across the switch to OFFBOARD"
BEFORE_REQUEST = "in the second before an offboard request"
SHORT_CONTEXT = {ACROSS_SWITCH: "across the switch", BEFORE_REQUEST: "before a request"}


def gap_severity(gap: float, timeout: float) -> Severity:
    """What a keep-alive gap in offboard does on a profile with this loss timeout."""
    if gap >= timeout:
        return Severity.ERROR
    if gap >= NEAR_LOSS_FRACTION * timeout:
        return Severity.WARNING
    return Severity.INFO


def _docs(ctx: CheckContext) -> str:
    """Which docs ask for 2 Hz: the release's own, or (1.18, whose docs give COM_OF_LOSS_T
    instead) the docs before and after it (gate spec 16 S12)."""
    if ctx.profile.release.docs_say_2hz:
        return "docs"
    return "docs before 1.18 and on main (1.18's give COM_OF_LOSS_T only)"


@dataclass(slots=True)
class _Gap:
    start: float
    end: float
    proven: float
    where: Where
    counts: float | None = None
    """The part of the gap PX4 acts on, where that is less than the whole (a gap that ends
    before a request: none; across a request PX4 refused: the keep-alive's age at it);
    None: all of it."""
    ignored: str = ""
    """The messages PX4 ignores that came in the gap (OFB608's), as "82 NAME", or ""."""


class KeepaliveRate(Check):
    """OFB101: gaps of 500 ms or more in offboard, or in the second before an offboard request."""

    codes = ("OFB101",)
    wants = (*KEEPALIVE_EVENTS, Command, CommandAck, VehicleStatus, *IGNORED)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.max_gap = float(ctx.option("OFB101", "max_gap_s"))
        self.quick = self.max_gap > PROOF_SLACK_S
        """Short gaps may skip ``proven_gap`` (see ``PROOF_SLACK_S``)."""
        self.window = float(ctx.option("OFB101", "pre_request_window_s"))
        self.last: float | None = None
        self.last_in_offboard = False
        self.dropout_since_last = False
        self.last_where = Where("keep-alive")
        self.switches = RecordedSwitches(ctx)
        self.request_in_gap: float | None = None
        """When an offboard request came while no keep-alive had arrived since ``last``."""
        self.recent: list[_Gap] = []
        """Gaps outside offboard, kept for ``window`` seconds in case a request follows."""
        self.left_at: Event | None = None
        """The ack of a switch away from OFFBOARD that ended the window while no keep-alive
        came: judged once no second ack can undo it (1.16/1.17 ack a switch twice, and only
        the last, Commander's, decides: gate.md#acks)."""
        self.count_ignored = ignores(ctx)
        self.ignored: list[tuple[float, str]] = []
        """(time, message name) of each message PX4 ignores since the newest keep-alive."""

    def on_event(self, event: Event) -> None:
        if isinstance(event, IGNORED):  # not a keep-alive: said with the gap it falls in
            if self.count_ignored and event.origin == "sent" and self.last is not None:
                self.ignored.append((event.t, message_name(event)))
            return
        state = self.ctx.state
        left = self.left_at
        if left is not None and (
            event is state.keepalive or event.t - left.t > DOUBLE_ACK_WINDOW_S
        ):
            self.left_at = None
            self._silence_until_left(left)
        if event is state.keepalive:  # first: nearly every message is one
            last = self.last
            if last is not None and not self.dropout_since_last:
                gap = event.t - last
                if not (self.quick and gap + PROOF_SLACK_S < self.max_gap):
                    self._gap(event, last, proven_gap(self.ctx, event, gap))
            self.last, self.last_where = event.t, event.where
            self.last_in_offboard = self.ctx.flying
            self.dropout_since_last = False
            self.request_in_gap = None
            self.ignored.clear()
        elif isinstance(event, Dropout):
            self.dropout_since_last = True
        else:
            if isinstance(event, Command):
                if event.is_offboard_switch or (event.is_arm and self.ctx.in_offboard):
                    self._request(event.t)
            elif isinstance(event, VehicleStatus) and self.switches.entered_by_request(
                event, self.last
            ):
                self._request(event.t)  # no commands recorded (MAVROS): the switch itself
            if isinstance(event, CommandAck):
                self._ack(event, left)
            elif self.last_in_offboard and not self.ctx.flying:
                # left at a recorded status, or (no mode recorded) at the command itself
                self.last_in_offboard = False
                self._silence_until_left(event)
        if self.recent:
            self.recent = [g for g in self.recent if event.t - g.end <= self.window]

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: only short gaps (under the limit whatever the logger's interval) and no
        gap outside offboard kept for a later request: just move ``last`` on. A gap kept in
        ``recent`` is trimmed by every message ``on_event`` sees, keep-alive or not (a MAVLink
        setpoint for another vehicle): replay then."""
        if self.recent or self.left_at is not None:
            self.replay(batch)
            return
        keepalives = batch.keepalives()
        if not keepalives:
            return
        if not self.quick:
            self.replay(batch)
            return
        last = None if self.dropout_since_last else self.last
        if keepalive_run(batch).worst_gap(last) + PROOF_SLACK_S >= self.max_gap:
            self.replay(batch)
            return
        newest = keepalives[-1]
        self.last, self.last_where = newest.t, newest.where
        self.last_in_offboard = self.ctx.flying
        self.dropout_since_last = False
        self.request_in_gap = None
        self.ignored.clear()

    def _ack(self, ack: CommandAck, left: Event | None) -> None:
        if self.last_in_offboard and not self.ctx.flying:
            # a switch away accepted at this ack: the window ends here, not at the next status
            # message (PX4's HEARTBEAT is 1 Hz)
            self.last_in_offboard = False
            self.left_at = ack
        elif left is not None and self.left_at is left and self.ctx.flying:
            # Commander's ack after the receiver's rejects the switch: still in OFFBOARD
            self.last_in_offboard = True
            self.left_at = None

    def _ignored_in(self, end: float) -> str:
        """The messages PX4 ignores that came up to ``end`` since the newest keep-alive."""
        names = [name for t, name in self.ignored if t <= end]
        if not names:
            return ""
        return ", ".join(f"{n} {name}" for name, n in Counter(names).items())

    def _gap(self, event: Event, last: float, proven: float) -> None:
        if proven >= self.max_gap:
            found = _Gap(last, event.t, proven, event.where, ignored=self._ignored_in(event.t))
            ctx = self.ctx
            if self.last_in_offboard:
                self._report(found, IN_OFFBOARD)
            elif self.request_in_gap is not None or ctx.flying:
                # PX4 judges the newest keep-alive's age, whenever the silence began: flying in
                # OFFBOARD at its end, the whole gap counts; else its age at the request
                asked = self.request_in_gap
                if not ctx.flying and asked is not None:
                    # in OFFBOARD but disarmed (1.14+ accepts that switch): nothing flies
                    found.counts = 0.0 if ctx.in_offboard else asked - last
                self._report(found, ACROSS_SWITCH)
            else:
                self.recent.append(found)

    def _silence_until_left(self, event: Event) -> None:
        """The vehicle left OFFBOARD (or disarmed) at ``event`` with no keep-alive since
        ``last``: only the part of the silence spent in OFFBOARD counts."""
        if self.last is None or self.dropout_since_last:
            return
        gap = proven_gap(self.ctx, event, event.t - self.last)
        if gap >= self.max_gap:
            found = _Gap(self.last, event.t, gap, self.last_where)
            found.ignored = self._ignored_in(event.t)
            self._report(found, f"{IN_OFFBOARD} (until it left)")

    def _request(self, t: float) -> None:
        if self.last is not None and self.request_in_gap is None:
            self.request_in_gap = t  # a silence still open at the request
        for found in self.recent:
            if t - found.end <= self.window:
                found.counts = 0.0
                self._report(found, BEFORE_REQUEST)
        self.recent.clear()

    def _report(self, gap: _Gap, context: str) -> None:
        """Say both what the docs require and what PX4 does; the severity is what PX4 does
        with the part of the gap it acts on (``_Gap.counts``, ``gap_severity``)."""
        ctx = self.ctx
        timeout = loss_timeout(ctx)
        sampled = " (logged gap minus the logger's interval)" if ctx.info.sampled else ""
        head = (
            f"keep-alive gap of {gap.proven:.2f} s{sampled} {context}{mode_note(ctx)}; "
            f"{_docs(ctx)}: keep-alive at > 2 Hz, gaps under {self.max_gap:.1f} s; "
            f"{px4_label(ctx)}"
        )
        flown = gap.proven if gap.counts is None else min(gap.proven, gap.counts)
        severity = gap_severity(flown, timeout)
        if severity is Severity.ERROR and gap.counts is not None:
            message = (
                f"{head} refuses the request: its newest keep-alive was {flown:.2f} s old "
                f"(loss timeout {timeout:.2f} s)"
            )
            verdict = "refuses the request"
        elif severity is Severity.ERROR:
            message = f"{head} loses the offboard signal after {timeout:.2f} s"
            verdict = f"loses the signal at {timeout:.2f} s"
        elif gap.counts is not None and flown < self.max_gap:
            message = (
                f"{head} judges only the newest keep-alive's age at the request (loss timeout "
                f"{timeout:.2f} s): OFB102 and OFB201 say what it does with the request"
            )
            verdict = "judges only the keep-alive's age at the request"
        else:
            margin = " (only just)" if severity is Severity.WARNING else ""
            message = (
                f"{head} would: keep the offboard signal{margin}, it is lost only after a gap "
                f"of COM_OF_LOSS_T = {timeout:.2f} s"
            )
            just = ", only just" if margin else ""
            verdict = f"keeps the signal{just} (lost at {timeout:.2f} s)"
        if as_received(ctx) and severity is not Severity.INFO:
            message += f"; {RECEIVED_NOTE}"
        place = context.partition(" (")[0]  # "in OFFBOARD (until it left)": the place only
        place = SHORT_CONTEXT.get(place, place)
        short = f"keep-alive gap {gap.proven:.2f} s {place}; {px4_label(ctx)} {verdict}"
        if gap.ignored:
            # what the sender did send meanwhile, and what PX4 made of it
            message += (
                f"; in the gap came {gap.ignored}, which {px4_label(ctx)} ignores: no "
                "keep-alive (OFB608)"
            )
            short += f"; {gap.ignored} in it, ignored"
        ctx.report(
            "OFB101", message, gap.start, gap.where, severity=severity, end=gap.end, short=short
        )

    def finish(self, t_end: float) -> None:
        left, self.left_at = self.left_at, None
        if left is not None:
            self._silence_until_left(left)
        elif self.last is not None and self.last_in_offboard and t_end - self.last >= self.max_gap:
            found = _Gap(self.last, t_end, t_end - self.last, self.last_where)
            found.ignored = self._ignored_in(t_end)
            self._report(found, f"{IN_OFFBOARD} (stream stopped, recording ends)")


class StreamBeforeRequest(Check):
    """OFB102: an offboard request without one second of unbroken keep-alive before it."""

    codes = ("OFB102",)
    wants = (*KEEPALIVE_EVENTS, Command, VehicleStatus, GateTransition)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.min_stream = float(ctx.option("OFB102", "min_stream_s"))
        self.max_gap = float(ctx.option("OFB101", "max_gap_s"))
        self.quick = self.max_gap > PROOF_SLACK_S
        """Short gaps may skip ``proven_gap`` (see ``PROOF_SLACK_S``)."""
        self.run_start: float | None = None
        self.last: float | None = None
        self.gate_verdict: dict[int, GateTransition] = {}
        self.switches = RecordedSwitches(ctx)
        self.held: tuple[Event, str, GateTransition, float | None, float | None] | None = None
        """A request the gate model rejected, held for one Commander iteration: PX4's flag may
        show, in the same iteration, the keep-alive a ULog's logger missed, and the model then
        judges the request again (its new verdict names the same command)."""

    def on_event(self, event: Event) -> None:
        held = self.held
        if held is not None:
            self._settle(event)
        if event is self.ctx.state.keepalive:  # first: nearly every message is one
            last = self.last
            if last is None:
                self.run_start = event.t
            else:
                gap = event.t - last
                short = self.quick and gap + PROOF_SLACK_S < self.max_gap
                if not short and proven_gap(self.ctx, event, gap) >= self.max_gap:
                    self.run_start = event.t
            self.last = event.t
        elif isinstance(event, GateTransition):
            if event.cause is not None and event.what in (
                "request_accepted",
                "request_rejected",
                "arm_accepted",
                "arm_rejected",
                "undecided",
            ):
                self.gate_verdict[id(event.cause)] = event
        elif isinstance(event, Command):
            if event.is_offboard_switch:
                self._judge(event, "switch to OFFBOARD")
            elif event.is_arm and self.ctx.offboard_selected():
                self._judge(event, "arm in OFFBOARD")
            self.gate_verdict.clear()
        elif isinstance(event, VehicleStatus) and self.switches.entered_by_request(
            event, self.last
        ):
            self._judge(event, "switch to OFFBOARD (recorded mode)")

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: no gap in the run (nor from ``last`` to it) can break the unbroken stream,
        as ``on_event`` tests it: only ``last`` moves (and ``run_start`` at the very first)."""
        if self.held is not None:
            self.replay(batch)  # any message may end the held request's iteration
            return
        if not batch.keepalives():
            return
        run = keepalive_run(batch)
        if not self.quick or run.worst_gap(self.last) + PROOF_SLACK_S >= self.max_gap:
            self.replay(batch)
            return
        if self.last is None:
            self.run_start = run.times[0]
        self.last = run.times[-1]

    def _settle(self, event: Event) -> None:
        """Report the held request once its iteration is over, or with the verdict the model
        gave it again (a later verdict naming the same command)."""
        assert self.held is not None
        request, what, verdict, last, run_start = self.held
        again = event if isinstance(event, GateTransition) else None
        if again is not None and again.cause is request and again.what.endswith("accepted"):
            self.held = None
            self._report(request, what, again, last, run_start)
        elif event.t - request.t > SAME_ITERATION_S:
            self.held = None
            self._report(request, what, verdict, last, run_start)

    def _judge(self, event: Event, what: str) -> None:
        verdict = self.gate_verdict.get(id(event))
        if verdict is not None and verdict.what.endswith("rejected"):
            if self.held is not None:
                self._report(*self.held)
            self.held = (event, what, verdict, self.last, self.run_start)
            return
        self._report(event, what, verdict, self.last, self.run_start)

    def _report(
        self,
        event: Event,
        what: str,
        verdict: GateTransition | None,
        last: float | None,
        run_start: float | None,
    ) -> None:
        """The finding for a request, with the keep-alive as it stood at the request."""
        t = event.t
        fresh = last is not None and t - last < self.max_gap
        if fresh and run_start is not None and t - run_start >= self.min_stream:
            return
        if last is None:
            had = "no keep-alive at all before it"
        elif not fresh:
            had = f"the last keep-alive {t - last:.2f} s before it"
        else:
            assert run_start is not None
            had = f"only {t - run_start:.2f} s of unbroken keep-alive before it"
        severity = Severity.INFO  # the docs' second: no PX4 release enforces it (D1)
        if verdict is None:
            would = (
                "the recording shows the vehicle's answer"
                if isinstance(event, VehicleStatus)
                else "see the gate timeline"
            )
            brief = ""
        elif verdict.what == "undecided":  # the arming state is not in the recording
            would = verdict.reason or verdict.message
            brief = "accepts it if disarmed, rejects it if armed"
        elif verdict.what.endswith("accepted"):
            would = "accept it"
            brief = "accepts it"
            if not fresh:
                # accepted only because the vehicle is disarmed (1.14+, D8): 1.13 and legacy
                # reject the same switch, and arming then needs a fresh keep-alive
                would += " (disarmed: accepted without a fresh keep-alive, checked at arming)"
                brief += " (disarmed)"
        else:
            would = f"reject it ({verdict.reason or verdict.message})"
            brief = "rejects it"
            severity = Severity.ERROR
        message = (
            f"{what} with {had}; docs: stream for at least {self.min_stream:.0f} s first; "
            f"{px4_label(self.ctx)} would: {would}"
        )
        received = as_received(self.ctx) and not fresh
        if received:
            message += f"; {RECEIVED_NOTE}"
        accepted = " PX4 accepted" if received else ""
        if last is None:
            stream = f"with no keep-alive{accepted}"
        elif not fresh:
            stream = f"{t - last:.2f} s after the last keep-alive{accepted}"
        else:
            stream = f"after {t - (t if run_start is None else run_start):.2f} s of keep-alive"
        short = f"{what} {stream} (docs: {self.min_stream:g} s of it)"
        if brief:
            short += f"; {px4_label(self.ctx)} {brief}"
        self.ctx.report("OFB102", message, t, event.where, severity=severity, short=short)

    def finish(self, t_end: float) -> None:
        if self.held is not None:
            self._report(*self.held)
            self.held = None


@cache
def _bin_start(ms: int) -> float:
    """The least gap that ``_Histogram.add`` puts in bin ``ms`` or above (``int(gap * 1000)``
    only grows with the gap): ``ms / 1000`` moved by the odd ulp that rounding takes."""
    gap = ms / 1000
    while int(gap * 1000) >= ms:
        gap = math.nextafter(gap, -math.inf)
    while int(gap * 1000) < ms:
        gap = math.nextafter(gap, math.inf)
    return gap


class _Histogram:
    """Gap counts in 1 ms bins up to the budget: bounded memory however long the stretch."""

    def __init__(self, budget: float) -> None:
        self.bins = [0] * (int(budget * 1000) + 2)
        self.top = len(self.bins) - 1
        self.count = 0
        self.worst = 0.0

    def add(self, gap: float) -> None:
        # min()/max() spelled out: this runs once per keep-alive message
        if gap < 0.0:
            return  # out-of-order times (a recording not in time order): not an interval
        ms = int(gap * 1000)
        self.bins[ms if ms < self.top else self.top] += 1
        self.count += 1
        if gap > self.worst:
            self.worst = gap

    def add_many(self, gaps: list[float]) -> None:
        """``add`` for each of ``gaps``, sorted and none negative: ``int(gap * 1000)`` never
        falls as the gap grows, so each bin's gaps are a block, ended by bisection."""
        start, end = 0, len(gaps)
        while start < end:
            ms = int(gaps[start] * 1000)
            stop = bisect_left(gaps, _bin_start(ms + 1), start, end)
            self.bins[ms if ms < self.top else self.top] += stop - start
            start = stop
        self.count += end
        if end and gaps[-1] > self.worst:
            self.worst = gaps[-1]

    def quantile(self, q: float) -> float:
        target = q * self.count
        seen = 0
        for ms, n in enumerate(self.bins):
            seen += n
            if seen >= target:
                return ms / 1000
        return self.worst


class KeepaliveMargin(Check):
    """OFB105: above 2 Hz but with little margin, per offboard stretch (heuristic; info: no
    PX4 release acts on the 2 Hz margin, the margin it acts on is the loss timeout, OFB101)."""

    codes = ("OFB105",)
    wants = KEEPALIVE_EVENTS

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.budget = float(ctx.option("OFB105", "budget_s"))
        self.worst_limit = self.budget * float(ctx.option("OFB105", "worst_fraction"))
        self.p99_limit = self.budget * float(ctx.option("OFB105", "p99_fraction"))
        self.min_intervals = int(ctx.option("OFB105", "min_intervals"))
        self.last: float | None = None
        self.stretch_start: float | None = None
        self.hist = _Histogram(self.budget)
        self.broken = False
        if ctx.info.sampled:
            self.subscriptions = ()
            ctx.cannot_check(
                "OFB105",
                "needs the keep-alive as sent (a ULog subsamples offboard_control_mode, "
                "hiding the sender's jitter)",
            )

    def on_event(self, event: Event) -> None:
        if event is not self.ctx.state.keepalive:
            return
        flying = self.ctx.flying
        if flying and self.stretch_start is None:
            self.stretch_start = event.t
        elif not flying and self.stretch_start is not None:
            self._close(event.t)
        if flying and self.last is not None and self.last >= (self.stretch_start or 0.0):
            gap = event.t - self.last
            if gap >= self.budget:
                self.broken = True  # OFB101 territory, not a margin problem
            else:
                self.hist.add(gap)
        self.last = event.t

    def on_batch(self, batch: StreamBatch) -> None:
        """The run's keep-alives all see the same ``flying``. Out of offboard only the first
        may close a stretch. In offboard the fast path needs time-ordered keep-alives, all
        after the stretch's start, and every gap under the budget: then each gap goes to the
        histogram as ``on_event`` would add it (``add_many``), in bulk."""
        if not batch.keepalives():
            return
        run = keepalive_run(batch)
        times = run.times
        if not self.ctx.flying:
            if self.stretch_start is not None:
                self._close(times[0])
            self.last = times[-1]
            return
        start = times[0] if self.stretch_start is None else self.stretch_start
        last = self.last
        first = None if last is None or not last >= start else times[0] - last
        if not (run.narrowest >= 0.0 and times[0] >= start and run.widest < self.budget) or (
            first is not None and not 0.0 <= first < self.budget
        ):
            self.replay(batch)  # a long or negative gap, or one before the stretch: rare
            return
        self.stretch_start = start
        if first is not None:
            self.hist.add(first)
        self.hist.add_many(run.gaps)
        self.last = times[-1]

    def _close(self, t: float) -> None:
        start = self.stretch_start
        hist = self.hist
        self.stretch_start, self.hist = None, _Histogram(self.budget)
        broken, self.broken = self.broken, False
        if start is None or broken or hist.count == 0:
            return
        reasons = []
        if hist.worst > self.worst_limit:
            reasons.append(
                f"worst gap {hist.worst * 1000:.0f} ms ({hist.worst / self.budget:.0%} of the "
                f"{self.budget * 1000:.0f} ms budget)"
            )
        if hist.count >= self.min_intervals:
            p99 = hist.quantile(0.99)
            if p99 > self.p99_limit:
                reasons.append(f"99th-percentile gap {p99 * 1000:.0f} ms")
        if reasons:
            message = (
                f"keep-alive above 2 Hz but marginal over {hist.count} intervals in OFFBOARD"
                f"{mode_note(self.ctx)}: " + "; ".join(reasons)
            )
            self.ctx.report("OFB105", message, start, Where("keep-alive"), end=t)

    def finish(self, t_end: float) -> None:
        if self.stretch_start is not None:
            self._close(t_end)
