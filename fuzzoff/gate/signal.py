"""Proof of life: when is the offboard signal available, per profile (gate.md#signal).

Each model keeps only the newest keep-alive and computes the time of its loss arithmetically
(no per-tick loop):

* ``TickSignal`` (1.14+, 2.1): lost at the first 10 Hz check pass at or after
  ``newest + COM_OF_LOSS_T`` (or after the newest keep-alive turned bad), i.e. within one check
  period after it; available again at the keep-alive that arrives while lost (2.1.3: the forced
  check pass). ``lost_at`` is the window's start; the model dates the loss there with the
  window, or waits (``hold``) for PX4's own verdict where the recording holds it.
* ``HysteresisSignal`` (1.13, 2.2): Commander iterations every 10 ms; lost once no good keep-alive
  was seen for ``COM_OF_LOSS_T`` counted from the first iteration without one.
* ``AgeSignal`` (1.11, 2.2): lost at the first iteration where the keep-alive's age is
  ``>= COM_OF_LOSS_T``; no flag or estimate conditions.
* ``LegacySignal`` (legacy, 2.3): lost 500 ms after the newest accepted message; a second stage,
  the loss timeout, ``COM_OF_LOSS_T`` later.

Commander iterations (1.11-1.13) are placed on a 10 ms grid anchored at the recording's time
zero: PX4's own phase is unknown, hence the evaluation slack of ``slack()``.
"""

from __future__ import annotations

import math

from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.ocm import ACCELERATION, ATTITUDE, POSITION, VELOCITY
from fuzzoff.releases import Release

INF = math.inf
CHECK_PERIOD = 0.1
"""Health-check pass period, 1.14+ (2.1.3)."""
LOOP_PERIOD = 0.01
"""Commander iteration (``COMMANDER_MONITORING_INTERVAL``), 1.11-1.13 (2.2)."""
LEGACY_TIMEOUT = 0.5
"""``OFFBOARD_TIMEOUT`` of legacy (2.3)."""
_EPS = 1e-9
_SAME_ITER = 1e-6


def grid_ceil(x: float, period: float) -> float:
    """The first grid point at or after ``x``."""
    return math.ceil(x / period - _EPS) * period


def slack(release: Release) -> float:
    """How late PX4 may see a loss compared with a continuous model (2.1.3: >= 110 ms on 1.14+;
    one Commander iteration plus one on older profiles)."""
    return 0.11 if release.tick_based else 2 * LOOP_PERIOD


def estimate_failure(release: Release, mask: int, est: Estimates) -> str | None:
    """Why the newest keep-alive's flags fail their estimate requirements (2.1 table, 2.2), or
    None. Every set flag is checked, not only the first (D10)."""
    if not release.control_mode_flags:
        return None
    if mask & POSITION and not est.local_position:
        return "no local position estimate (position flag)"
    if mask & VELOCITY and not est.local_velocity:
        return "no local velocity estimate (velocity flag)"
    if mask & ACCELERATION:
        if release.acceleration_needs_attitude:
            if not est.attitude:
                return "no attitude estimate (acceleration flag)"
        elif not est.local_velocity:
            return "no local velocity estimate (acceleration flag)"
    if release.attitude_flag_needs_attitude and mask & ATTITUDE and not est.attitude:
        return "no attitude estimate (attitude flag)"
    return None


def px4_stamp(t: float, sender_us: int, offset: float) -> float:
    """A ROS 2 message's ``timestamp`` as PX4 1.14+ reads it after its uXRCE-DDS rewrite
    (2.1.1): ``min(value - offset, now)``, a value below the offset wrapping to now. ``offset``
    is the sender's clock minus the recording's, in seconds; ``t`` the receive time. (A value
    of 0 is also the receive time; the caller knows it before it has an offset.)"""
    stamp = sender_us * 1e-6 - offset
    if stamp < 0.0:  # unsigned wrap in PX4: clamped to now
        return t
    return stamp if stamp < t else t


class Signal:
    """Common state: ``available`` and the newest keep-alive's time (``None`` before any)."""

    spec = "2"

    def __init__(self, timeout: float) -> None:
        self.timeout = timeout
        self.available = False
        self.last: float | None = None
        self.stale_stamp = False
        """The newest keep-alive arrived with a timestamp already older than the timeout."""
        self.arrived: float | None = None
        """When the newest keep-alive arrived (``last`` is its timestamp as PX4 sees it)."""
        self.moved_later = False
        """The newest stamped keep-alive (2.1.1) was good and moved the loss no earlier than
        the one before it (set by ``TickSignal``; False elsewhere)."""
        self.held_until = INF
        """``TickSignal.hold``: until when the model waits for PX4's recorded verdict on a loss
        (inf: not waiting; always inf elsewhere)."""

    @property
    def stamps_lag(self) -> bool:
        """Keep-alives still arrive but their timestamps lag by more than a check period."""
        if self.stale_stamp:
            return True
        return self.arrived is not None and self.last is not None and self.arrived - self.last > 0.1

    def keepalive(self, t: float, good: bool, stamp: float | None = None) -> bool:
        """A keep-alive at ``t`` (``good``: flags and estimates pass). True if it made the
        signal available."""
        raise NotImplementedError

    def turned_bad(self, t: float) -> None:
        """The newest keep-alive no longer passes (estimates changed at ``t``)."""

    def lost_at(self) -> float:
        """When the signal will be lost if nothing arrives (inf when not available)."""
        raise NotImplementedError

    def mark_lost(self) -> None:
        self.available = False
        self.held_until = INF

    def hold(self, until: float) -> None:
        """Wait for the recording to show PX4's verdict until ``until`` (``lost_at`` is inf
        meanwhile, where the subclass honours it); a good keep-alive ends the wait."""
        self.held_until = until

    def ok_now(self, t: float, good: bool) -> bool:
        """The condition evaluated right now (the arming path re-runs the checks, 4.2)."""
        return self.available and t < self.lost_at()

    def timeout_at(self) -> float:
        """Legacy's second stage (loss timeout); inf elsewhere."""
        return INF


class TickSignal(Signal):
    spec = "2.1"

    def __init__(self, timeout: float) -> None:
        super().__init__(timeout)
        self.bad_since: float | None = None

    def keepalive(self, t: float, good: bool, stamp: float | None = None) -> bool:
        """``stamp``: the OCM ``timestamp`` as PX4 sees it (2.1.1); the receive time if None.
        A sample already older than the timeout on arrival counts as bad."""
        before = self.last
        last = self.last = t if stamp is None else stamp
        self.arrived = t
        stale = t >= last + self.timeout
        if stamp is None:
            self.stale_stamp = False
        else:
            self.stale_stamp = good and stale
            # Available, good, not bad before and a stamp no older: lost_at() cannot move
            # earlier.
            self.moved_later = (
                good
                and not stale
                and self.available
                and self.bad_since is None
                and before is not None
                and last >= before
            )
        if not good or stale:
            if self.available and self.bad_since is None:
                self.bad_since = t
            return False
        self.bad_since = None
        self.held_until = INF  # a good keep-alive before PX4's check pass: no loss
        if not self.available:
            self.available = True
            return True
        return False

    def turned_bad(self, t: float) -> None:
        if self.available and self.bad_since is None:
            self.bad_since = t

    def lost_at(self) -> float:
        """The start of the loss window: from here the next check pass, within
        ``CHECK_PERIOD``, drops the signal (inf while held or not available)."""
        if not self.available or self.last is None or self.held_until != INF:
            return INF
        # Once the newest sample is bad (flags, estimates, an old stamp) the next check pass
        # after that moment drops the signal; otherwise the pass after its age reaches the
        # timeout.
        return self.bad_since if self.bad_since is not None else self.last + self.timeout

    def ok_now(self, t: float, good: bool) -> bool:
        return self.last is not None and good and t < self.last + self.timeout


class HysteresisSignal(Signal):
    spec = "2.2"

    def __init__(self, timeout: float) -> None:
        super().__init__(timeout)
        self.good_iter: float | None = None

    def keepalive(self, t: float, good: bool, stamp: float | None = None) -> bool:
        self.last = t
        if not good:
            return False
        self.good_iter = grid_ceil(t, LOOP_PERIOD)
        if not self.available:
            self.available = True
            return True
        return False

    def lost_at(self) -> float:
        if not self.available or self.good_iter is None:
            return INF
        # A message that arrives by the iteration itself keeps the candidate true: the loss
        # needs an iteration with no new message, hence "just after" the grid point.
        return grid_ceil(self.good_iter + LOOP_PERIOD + self.timeout, LOOP_PERIOD) + _SAME_ITER


class AgeSignal(Signal):
    spec = "2.2"

    def keepalive(self, t: float, good: bool, stamp: float | None = None) -> bool:
        self.last = t
        if not self.available and self.timeout > 0.0:
            self.available = True
            return True
        return False

    def lost_at(self) -> float:
        if not self.available or self.last is None:
            return INF
        return grid_ceil(self.last + self.timeout, LOOP_PERIOD)


class LegacySignal(Signal):
    """Two flags: lost (500 ms) and loss timeout (500 ms + ``COM_OF_LOSS_T``), gate.md#signal."""

    spec = "2.3"

    def __init__(self, timeout: float, loss_extra: float) -> None:
        super().__init__(timeout)
        self.loss_extra = loss_extra
        self.timed_out = False

    def keepalive(self, t: float, good: bool, stamp: float | None = None) -> bool:
        self.last = t
        self.timed_out = False
        if not self.available:
            self.available = True
            return True
        return False

    def lost_at(self) -> float:
        if not self.available or self.last is None:
            return INF
        return self.last + self.timeout

    def timeout_at(self) -> float:
        if self.timed_out or self.last is None:
            return INF
        extra = self.loss_extra if self.loss_extra >= 1.19e-7 else 0.0
        return self.last + self.timeout + extra


class UnseenSignal(Signal):
    """The signal of a recording that cannot show the keep-alive (a ground station's tlog):
    taken as available, never lost by a timeout; only PX4's own recorded failsafe drops it
    (``mark_lost``) and the vehicle shown in OFFBOARD again brings it back (``keepalive``)."""

    spec = "2"

    def __init__(self, timeout: float) -> None:
        super().__init__(timeout)
        self.available = True
        self.timed_out = True

    def keepalive(self, t: float, good: bool, stamp: float | None = None) -> bool:
        if self.available:
            return False
        self.available = True
        return True

    def lost_at(self) -> float:
        return INF

    def ok_now(self, t: float, good: bool) -> bool:
        return self.available


def make_signal(release: Release, params: dict[str, float]) -> Signal:
    timeout = max(0.0, float(params.get("COM_OF_LOSS_T", 1.0)))
    if release.loss_signal == "fixed":
        fixed = LEGACY_TIMEOUT if release.fixed_loss_s is None else release.fixed_loss_s
        return LegacySignal(fixed, timeout)
    if release.loss_signal == "age":
        return AgeSignal(timeout)
    if release.loss_signal == "hysteresis":
        return HysteresisSignal(timeout)
    return TickSignal(timeout)
