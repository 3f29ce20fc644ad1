"""The keep-alives and the loss of the offboard signal (gate.md#signal): one part of ``GateModel``.

``KeepAlives`` takes every keep-alive (``OffboardControlMode``, its legacy form, and the MAVLink
setpoints ``mavlink.MavlinkSetpoints`` passes on), says when the signal becomes available,
and dates its loss when the signal's deadline comes: on 1.14+ within PX4's 10 Hz check window,
or where the recording shows PX4's own verdict (``verdict``) or failsafe (``history``). The
failsafe that answers the loss is ``effective.EffectiveMode``'s.
"""

from __future__ import annotations

from fuzzoff.events import NAV_STATE_OFFBOARD, ControlMode, Event, LegacyControlMode
from fuzzoff.gate import ocm
from fuzzoff.gate.compare import SAMPLED_SLACK
from fuzzoff.gate.effective import EffectiveMode
from fuzzoff.gate.setpoints import Controllers
from fuzzoff.gate.signal import CHECK_PERIOD, INF, LOOP_PERIOD, estimate_failure, px4_stamp
from fuzzoff.gate.state import GateState

RECORDED_FAILSAFE = "PX4's failsafe recorded then"
NOT_FLAGGED = "the model's alone: PX4's failsafe_flags shows no loss"
"""``seen_in`` of a loss the recording's flag of PX4 contradicts (a disagreement follows)."""
FLAG_FRESH_S = 1.0
"""PX4 publishes ``failsafe_flags`` at each change and about every 0.5 s: a recording whose
newest sample is older than this does not show PX4's verdict any more."""


class KeepAlives:
    def __init__(self, state: GateState, mode: EffectiveMode, controllers: Controllers) -> None:
        self.s = state
        self.mode = mode
        self.controllers = controllers
        self.sampled = False
        """The keep-alive is a logged, subsampled copy (a ULog's ``offboard_control_mode``)."""
        self.flags_ignored = not state.release.control_mode_flags
        """Before 1.13 any keep-alive counts, whatever its flags (2.2)."""
        self.window: tuple[float, float] | None = None
        """1.14+: the current loss window (its start, the latest check pass), while held."""
        self.flag_shows = False
        """The current loss window is one PX4's recorded flag will date."""
        self.stamp_offset: float | None = None
        """The sender's clock minus the recording's (the first stamped keep-alive's)."""

    # -- keep-alives

    def control_mode(self, event: ControlMode) -> bool:
        stamp = None
        if self.s.tick_based and event.origin == "sent" and event.sender_time_us is not None:
            stamp = self._px4_stamp(event.t, event.sender_time_us)
        return self.keepalive(event.t, ocm.mask_of(event), event, stamp)

    def legacy_control_mode(self, event: LegacyControlMode) -> bool:
        return self.keepalive(event.t, ocm.legacy_mask(event), event)

    def _px4_stamp(self, t: float, sender_us: int) -> float:
        """The OCM ``timestamp`` after PX4's uXRCE-DDS rewrite (2.1.1): 0 becomes the receive
        time, any other value ``min(value - offset, now)``. The agent-PX4 offset is unknown;
        fuzzoff takes the first stamped keep-alive as fresh (a sender clock that runs with the
        recording's is always fresh; one that stops or lags ages)."""
        if sender_us == 0:
            return t
        if self.stamp_offset is None:
            self.stamp_offset = sender_us * 1e-6 - t
        return px4_stamp(t, sender_us, self.stamp_offset)

    def keepalive(self, t: float, mask: int, event: Event, stamp: float | None = None) -> bool:
        """A keep-alive with flags ``mask``; True when the model's deadlines may have moved
        earlier (``GateModel.feed`` then recomputes them)."""
        s = self.s
        if mask == s.ocm_mask and s.good and (self.sampled or event.origin != "vehicle"):
            # The steady stream: same flags, good, sampling settled: only the signal moves. A
            # good keep-alive received now while available only moves the loss later: the
            # cached deadline stays a valid lower bound (feed() recomputes it when it is
            # reached). One with its own timestamp (2.1.1) may lag and move the loss earlier
            # (the signal says).
            if s.signal.keepalive(t, True, stamp):
                self.available(t, mask)
                return True
            return stamp is not None and not s.signal.moved_later
        s.flags_unlogged = False
        changed = mask != s.ocm_mask
        if changed:
            s.ocm_mask = mask
            self.mask_changed()
        if event.origin == "vehicle" and not self.sampled:
            self.sampled = True
            s.compare.sampled_keepalive()
        if s.signal.keepalive(t, s.good, stamp):
            self.available(t, mask)
        if changed:
            self.controllers.update(t)
        return True  # a new mask, a bad keep-alive or a newly available signal

    def mask_changed(self) -> None:
        """Recompute what depends only on the OCM flags and the estimates (cached: the hot path
        is one keep-alive per message)."""
        s = self.s
        mask = s.ocm_mask
        if self.flags_ignored:
            s.good = True
        else:
            s.good = mask != 0 and estimate_failure(s.release, mask, s.est) is None
        s.ctl.set_mask(mask)

    def estimates_changed(self, t: float) -> None:
        """The estimates changed: the newest keep-alive may no longer pass (2.1)."""
        s = self.s
        self.mask_changed()
        if s.tick_based and estimate_failure(s.release, s.ocm_mask, s.est):
            s.signal.turned_bad(t)

    def available(self, t: float, mask: int | None, seen_in: str | None = None) -> None:
        """The signal is available at ``t``. ``mask`` None: the keep-alive's flags are not in
        the recording yet."""
        s = self.s
        s.failsafe_due = INF
        self.window = None
        s.timing = (None, None)
        s.signal_changed(t)
        what = [] if mask is None else [ocm.names(mask)]
        what += [seen_in] if seen_in else []
        s.emit(
            t,
            "signal_available",
            f"offboard signal available ({'; '.join(what)})",
            s.signal.spec,
            seen_in=seen_in,
        )
        self.mode.refresh(t)

    # -- the loss

    def held_until(self) -> float:
        """1.14+: the end of the window held for PX4's recorded verdict (inf if none)."""
        return self.s.signal.held_until

    def lost(self, t: float) -> None:
        """The loss is due at ``t``. On 1.14+ PX4's 10 Hz check pass sees it within one check
        period (2.1.3), at a phase only the recording can show: the model waits to the end of
        that window (``hold``). PX4's flag or its failsafe recorded meanwhile dates the loss;
        a good keep-alive meanwhile ends it with no loss (PX4 flags one only if its pass fell
        before it); otherwise the loss is the window, dated at its end."""
        s = self.s
        if not s.tick_based:
            self.lose(t)
            return
        self.window = (t, t + CHECK_PERIOD)
        wait = CHECK_PERIOD
        self.flag_shows = s.flag_recorded and t - s.flag_at <= FLAG_FRESH_S
        if self.flag_shows:
            # PX4's flag will say: allow one iteration, and one logging interval where the
            # keep-alive is a logged subsample that may hide the stream's last messages.
            wait += LOOP_PERIOD + (SAMPLED_SLACK if self.sampled else 0.0)
        s.signal.hold(t + wait)

    def not_shown(self, t: float) -> None:
        """The window passed with no keep-alive: the loss is the window, or, where the
        recording holds PX4's flag and it has not flipped, the model's own verdict (a flag
        that still says available becomes a disagreement)."""
        window = self.window or (t, t)
        self.lose(t, window, NOT_FLAGGED if self.flag_shows else None)

    def shown(self, t: float, seen_in: str) -> None:
        """The recording shows PX4's loss at ``t`` (``seen_in``) while the window is held."""
        self.lose(t, self.window, seen_in)

    def lose(
        self,
        t: float,
        window: tuple[float, float] | None = None,
        seen_in: str | None = None,
    ) -> None:
        """The signal is lost at ``t``: ``window`` is PX4's check-pass window (1.14+),
        ``seen_in`` where the recording shows PX4's verdict when ``t`` comes from there."""
        s = self.s
        self.window = None
        s.signal.mark_lost()
        s.signal_changed(t)
        why = self._why_lost()
        reason = why or "keep-alive timeout"
        when, earliest = _loss_when(t, window, seen_in)
        age = ""
        last = s.signal.last
        if why is None and last is not None:
            start = t if earliest is None else earliest
            span = f"{t - last:.2f}" if start == t else f"{start - last:.2f}-{t - last:.2f}"
            age = f", {span} s after the newest keep-alive"
        s.emit(
            t,
            "signal_lost",
            f"offboard signal lost ({reason}){when}{age}{self._unknown_arming_note()}",
            s.signal.spec,
            cause=None,
            reason=reason,
            t_earliest=earliest,
            seen_in=seen_in,
        )
        if s.signal.timeout_at() <= t:  # legacy: COM_OF_LOSS_T 0 = both stages at once
            s.signal.timed_out = True  # type: ignore[attr-defined]
        if s.tick_based:
            # 1.14+ (2.1.3): Commander's iteration runs handleModeIntentionAndFailsafe() before
            # the check block, so the failsafe reacts one iteration (10 ms) after the check pass
            # that saw the loss. Until then nothing changes the mode, and a keep-alive that
            # arrives in between cancels it (the forced check pass clears the flag). Emitting
            # it only when that iteration is reached keeps the timeline in time order.
            s.failsafe_due = t + LOOP_PERIOD
            s.timing = (None if earliest is None else earliest + LOOP_PERIOD, seen_in)
        else:
            self.mode.refresh(t, cause=None)

    def _why_lost(self) -> str | None:
        """Why the newest keep-alive stopped counting (its flags, estimates or stamp), or None
        (it is only old: a timeout)."""
        s = self.s
        why = estimate_failure(s.release, s.ocm_mask, s.est) if s.tick_based else None
        if why is None and s.ocm_mask == 0 and s.signal.last is not None and not self.flags_ignored:
            why = "no flag set in the newest keep-alive"
        if why is None and s.tick_based and s.signal.stamps_lag:
            why = "the newest keep-alive's timestamp is older than COM_OF_LOSS_T (2.1.1)"
        return why

    def _unknown_arming_note(self) -> str:
        """A loss in OFFBOARD while the arming state is unknown: the failsafe runs only if
        armed (1.14+: none while disarmed, 4.1)."""
        s = self.s
        if not (s.tick_based and s.armed is None):
            return ""
        if s.user_intention != NAV_STATE_OFFBOARD:
            return ""
        action = s.loss_action()
        return f"; arming not recorded: if armed, PX4 runs {action.action}, if disarmed nothing"


def _loss_when(
    t: float, window: tuple[float, float] | None, seen_in: str | None
) -> tuple[str, float | None]:
    """The time words of a loss and the window's start (None: ``t`` is the time)."""
    if window is None:
        return "", None
    start, end = window
    if seen_in == NOT_FLAGGED:
        return (
            f" by {end:.3f} s (the model's window {start:.3f}-{end:.3f} s; PX4's "
            f"failsafe_flags shows no loss by {t:.3f} s)",
            None,
        )
    if seen_in is not None:
        at = "by" if seen_in == RECORDED_FAILSAFE else "at"
        return f" {at} {t:.3f} s ({seen_in}; the model's window {start:.3f}-{end:.3f} s)", None
    return (
        f" between {start:.3f} and {end:.3f} s (PX4 checks at 10 Hz; the check's phase is "
        "not in the recording)",
        start,
    )
