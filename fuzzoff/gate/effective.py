"""The effective mode and the loss action (gate.md#loss): one part of ``GateModel``.

``EffectiveMode`` works out the nav_state PX4 flies after anything that can change it: the user
intention, or, while the intention is OFFBOARD and the signal is lost, the action the loss
failsafe selects (``failsafe.loss_action``, per release and vehicle type), until the signal is
back. Termination is never left.
"""

from __future__ import annotations

from typing import Any

from fuzzoff.events import NAV_STATE_OFFBOARD, Event
from fuzzoff.gate.failsafe import LossAction
from fuzzoff.gate.setpoints import Controllers
from fuzzoff.gate.signal import INF
from fuzzoff.gate.state import GateState
from fuzzoff.releases import LossFailsafe

TERMINATION = 13
_RESUME_SPEC: dict[LossFailsafe, str] = {
    "framework": "5.1",
    "state_machine": "5.2",
    "state_machine_legacy": "5.3",
}
"""The section number (``gate.sections``) of the return to OFFBOARD when the signal comes back,
by loss failsafe."""


class EffectiveMode:
    def __init__(self, state: GateState, controllers: Controllers) -> None:
        self.s = state
        self.controllers = controllers

    def refresh(self, t: float, cause: Event | bool | None = True) -> None:
        """Recompute the effective nav_state after anything that can change it (``cause``:
        True for the event being fed, else the cause of what this emits)."""
        s = self.s
        kwargs: dict[str, Any] = {} if cause is True else {"cause": cause}
        if s.terminated:
            new: int | None = TERMINATION
        elif self._needs_failsafe():
            stage = 2 if getattr(s.signal, "timed_out", True) else 1
            if s.fallback is None or s.fallback_stage != stage:
                action = s.loss_action(stage)
                s.fallback = action
                s.fallback_stage = stage
                self._failsafe(t, action, kwargs)
            action = s.fallback
            new = action.nav_state if action.nav_state is not None else NAV_STATE_OFFBOARD
            if action.nav_state == TERMINATION:
                s.terminated = True
        else:
            if s.fallback is not None:
                self._resume(t, kwargs)
            new = s.user_intention if s.user_intention is not None else s.nav
        self.set_nav(t, new)

    def _needs_failsafe(self) -> bool:
        s = self.s
        if s.user_intention != NAV_STATE_OFFBOARD or s.signal.available:
            return False
        if s.failsafe_due != INF:
            return False  # lost at the last check pass; the failsafe iteration is still ahead
        if s.tick_based:
            return s.armed is True  # unknown: the signal_lost row says both
        return True  # 1.13 and older: recomputed even when disarmed (4.1)

    def _failsafe(self, t: float, action: LossAction, kwargs: dict[str, Any]) -> None:
        s = self.s
        note = f" ({action.note})" if action.note else ""
        disarmed = " while disarmed" if s.armed is False else ""
        earliest, seen_in = s.timing
        s.timing = (None, None)
        when = ""
        if earliest is not None:
            when = f" between {earliest:.3f} and {t:.3f} s"
        elif seen_in is not None:
            when = f" at {t:.3f} s ({seen_in})"
        s.fallback_when = when or f" at {t:.3f} s"
        s.emit(
            t,
            "failsafe",
            f"offboard loss{disarmed}{when}: {action.action}{note}",
            action.spec,
            action=action.action,
            nav_state=action.nav_state if action.nav_state is not None else s.nav,
            unverified=action.unverified,
            t_earliest=earliest,
            seen_in=seen_in,
            **kwargs,
        )
        if action.disarm and s.armed is not False:
            s.disarmed_now()
            s.emit(t, "disarmed", "disarmed by the offboard-loss action", action.spec, **kwargs)

    def _resume(self, t: float, kwargs: dict[str, Any]) -> None:
        """The failsafe ends: the signal is back (or the intention changed)."""
        s = self.s
        s.fallback = None
        s.fallback_stage = 0
        if s.user_intention == NAV_STATE_OFFBOARD and (s.armed is True or not s.tick_based):
            s.emit(
                t,
                "offboard_resumed",
                "offboard signal back: OFFBOARD again (the user intention never changed)",
                _RESUME_SPEC[s.release.loss_failsafe],
                nav_state=NAV_STATE_OFFBOARD,
                **kwargs,
            )

    def set_nav(self, t: float, new: int | None) -> None:
        s = self.s
        if new == s.nav:
            return
        s.compare.nav_changed(t, s.nav, new)
        s.nav = new
        if new == NAV_STATE_OFFBOARD:
            s.ctl.entered_offboard(t)
            s.offboard_since = t
        else:
            s.offboard_since = None
        self.controllers.update(t)

    # -- deadlines

    def failsafe_due(self) -> float:
        """1.14+: the Commander iteration that runs the loss failsafe (inf if none)."""
        return self.s.failsafe_due

    def failsafe_iteration(self, t: float) -> None:
        """The Commander iteration after the check pass that saw the loss: the failsafe runs
        now if the vehicle is armed (it consumes the loss's timing); else nothing is dated."""
        self.s.failsafe_due = INF
        self.refresh(t, cause=None)
        self.s.timing = (None, None)

    def timed_out(self, t: float) -> None:
        """legacy: the loss timeout came (``signal.timeout_at``), the failsafe's second stage."""
        self.s.signal.timed_out = True  # type: ignore[attr-defined]
        self.refresh(t)
