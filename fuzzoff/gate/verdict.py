"""PX4's own verdict on the offboard signal, as the recording shows it: one part of ``GateModel``.

Two recordings, two jobs:

* ``RecordedFlag``: the recording holds the stream and PX4's
  ``failsafe_flags.offboard_control_signal_lost`` (a ULog, 1.14+). The flag dates a loss the
  model holds a check window for (``keepalive.KeepAlives``), turns the signal available where
  the logger missed the keep-alive, and a value the model does not reach within the slack is a
  ``disagreement``.
* ``UnseenStream``: the recording cannot show the stream (a ground station's tlog). The signal
  is PX4's flag where the recording has it; else it is taken as present, lost where PX4's own
  failsafe is recorded (its status, a STATUSTEXT) and back when OFFBOARD is recorded again.
"""

from __future__ import annotations

from fuzzoff.events import NAV_STATE_OFFBOARD, FailsafeFlags, StatusText, VehicleStatus
from fuzzoff.gate.commander import Requests
from fuzzoff.gate.effective import EffectiveMode
from fuzzoff.gate.keepalive import KeepAlives
from fuzzoff.gate.signal import INF
from fuzzoff.gate.state import GateState

FAILSAFE_TEXT_WINDOW_S = 3.0
"""A failsafe STATUSTEXT this long before a recorded change out of OFFBOARD explains it (PX4
sends the text at once; the 1 Hz HEARTBEAT shows the new mode up to a second later)."""


class RecordedFlag:
    def __init__(self, state: GateState, keepalives: KeepAlives, requests: Requests) -> None:
        self.s = state
        self.keepalives = keepalives
        self.requests = requests
        self.episode = False
        """A flag difference was reported and the two have not agreed since."""
        self.was: bool | None = None
        """The flag's previous recorded value."""

    def flags(self, event: FailsafeFlags) -> None:
        """``failsafe_flags.offboard_control_signal_lost`` is PX4's verdict on the signal: a
        value the model does not reach within the evaluation slack is a disagreement (2.1).
        Judged while OFFBOARD is selected (recorded or predicted), where the verdict decides
        the mode; elsewhere it only matters to a switch request, which the acks judge."""
        s = self.s
        recorded = event.offboard_control_signal_lost
        if recorded is None:
            return
        flipped = self.was is True and not recorded
        self.was = recorded
        s.flag_at = event.t
        if s.tick_based:
            s.flag_recorded = True
            if recorded and s.signal.held_until != INF:
                self.keepalives.shown(event.t, "PX4's failsafe_flags")
            elif flipped and self._back(event.t):
                return
        if recorded == (not s.signal.available):
            s.flag_pending = None
            self.episode = False
            return
        if self.episode or s.flag_pending is not None:
            return
        status = s.compare.last_status
        seen = (status.nav_state, status.user_intention) if status is not None else ()
        if not s.involves_offboard(*seen):
            return
        if event.t - s.sig_changed_at <= s.compare.slack:
            return  # the log lags the model's own change
        s.flag_pending = (event.t, recorded, event)

    def _back(self, t: float) -> bool:
        """PX4's flag has just turned to available before the logger's subsampled copy of the
        keep-alive arrives (13a: its first samples can be missing): the signal is available at
        the flag's time. Not where the model lost it because the keep-alive stopped counting."""
        s = self.s
        if s.signal.available or (s.signal.last is not None and not s.good):
            return False  # a keep-alive that stopped counting (flags, estimates) is not lag
        first = s.signal.last is None
        if not s.signal.keepalive(t, True):
            return False
        mask = None if first else s.ocm_mask
        s.flags_unlogged = first
        self.keepalives.available(t, mask, "PX4's failsafe_flags; the logged keep-alive follows")
        self.requests.rejudge(t)
        return True

    def due(self) -> float:
        """When a recorded difference waiting for the slack is confirmed (inf if none)."""
        pending = self.s.flag_pending
        return INF if pending is None else pending[0] + self.s.compare.slack

    def differs(self, at: float) -> None:
        """The difference outlasted the slack: a disagreement, dated when it was recorded."""
        s = self.s
        pending, s.flag_pending = s.flag_pending, None
        if pending is None:
            return
        t, recorded, event = pending
        self.episode = True
        model = "available" if s.signal.available else "lost"
        last = s.signal.last
        age = f", newest keep-alive at {last:.2f} s" if last is not None else ", no keep-alive"
        s.emit(
            t,
            "disagreement",
            f"recorded: offboard_control_signal_lost {str(recorded).lower()} at {t:.2f} s "
            f"(PX4's own verdict); model: offboard signal {model}{age}",
            s.signal.spec,
            cause=event,
        )


class UnseenStream:
    def __init__(self, state: GateState, mode: EffectiveMode) -> None:
        self.s = state
        self.mode = mode
        self.failsafe_text_at = -INF
        """When PX4 last said a failsafe began (STATUSTEXT)."""

    @property
    def watching(self) -> bool:
        """Does the recorded mode history decide the signal (no stream, no flag of PX4)?"""
        return not self.s.stream_recorded and not self.s.follows_flag

    def start(self, t: float) -> None:
        """The recording's first status: say how the signal is taken."""
        if self.watching:
            self.s.emit(
                t,
                "signal_available",
                "offboard signal taken as present: the recording holds no keep-alive sent to "
                "the vehicle; PX4's recorded offboard_control_signal_lost decides it where "
                "the recording has it, else only a failsafe PX4 recorded counts as its loss",
                self.s.signal.spec,
            )

    def status_text(self, text: StatusText) -> bool:
        if not self.s.stream_recorded and "failsafe" in text.text.lower():
            self.failsafe_text_at = text.t
        return False

    def flags(self, event: FailsafeFlags) -> None:
        """PX4's own verdict is the signal: the flag is what Commander's check pass decided,
        and the failsafe follows it in the same iteration."""
        s = self.s
        lost = event.offboard_control_signal_lost
        if lost is None:
            return
        s.follows_flag = True
        t = event.t
        if lost and s.signal.available:
            s.signal.mark_lost()
            s.signal_changed(t)
            reason = "PX4's recorded offboard_control_signal_lost (the stream is not recorded)"
            s.emit(t, "signal_lost", f"offboard signal lost: {reason}", "2", reason=reason)
            self.mode.refresh(t)
        elif not lost and s.signal.keepalive(t, True):
            s.signal_changed(t)
            s.emit(
                t,
                "signal_available",
                "offboard signal available: PX4's recorded offboard_control_signal_lost "
                "(the stream is not recorded)",
                "2",
            )
            self.mode.refresh(t)

    def lost_in(self, status: VehicleStatus) -> None:
        """PX4's own failsafe is the loss: OFFBOARD left with no command for it, while PX4
        says a failsafe is active (``failsafe`` in the status, or a STATUSTEXT just before)."""
        s = self.s
        t = status.t
        if (
            not self.watching
            or status.nav_state is None
            or status.nav_state == NAV_STATE_OFFBOARD
            or not s.signal.available
            or s.user_intention != NAV_STATE_OFFBOARD
            or s.compare.recent_command(t)
        ):
            return
        text_before = 0.0 <= t - self.failsafe_text_at <= FAILSAFE_TEXT_WINDOW_S
        if not (status.failsafe is True or text_before):
            return
        said = f"STATUSTEXT at {self.failsafe_text_at:.2f} s" if text_before else "its status"
        s.signal.mark_lost()
        s.signal_changed(t)
        reason = f"PX4's recorded failsafe ({said}; the stream is not in the recording)"
        s.emit(
            t,
            "signal_lost",
            f"offboard signal lost: {reason}",
            s.signal.spec,
            cause=status,
            reason=reason,
        )
        self.mode.refresh(t, cause=status)

    def back_in(self, status: VehicleStatus) -> None:
        """The vehicle shown in OFFBOARD again is the signal back."""
        s = self.s
        t = status.t
        if self.watching and status.nav_state == NAV_STATE_OFFBOARD and s.signal.keepalive(t, True):
            s.signal_changed(t)
            s.emit(
                t,
                "signal_available",
                "recorded: OFFBOARD again (the stream is not in the recording)",
                s.signal.spec,
            )
            self.mode.refresh(t)
