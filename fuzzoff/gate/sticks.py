"""The sticks taking over OFFBOARD (gate spec 16 S1): one part of ``GateModel``.

What PX4 does, per release (``Release.stick_override``), as seen on SITL (MAVLink joystick,
2026-12):

* 1.18 and main (``MAN_OVERRIDE_SPD``, default 1 per second; negative: off): ManualControl sets
  ``manual_control_setpoint.sticks_moving`` when a stick moves faster than the threshold *and*
  in one direction for at least three samples in a row. A step (one big change, then none) and
  a fast swing (the direction changes every sample or two) never count; a steady ramp does.
  Commander then makes Position the user intention of an armed multicopter (VTOL in hover) in
  OFFBOARD without an active failsafe: OFFBOARD ends and does not come back by itself. Seen on
  the 1.18 head and main bundles (``corpora/sitl/sticks_moved-*``).
* 1.14-1.17 (``COM_RC_OVERRIDE``, default 1 = auto modes only; bit 1 adds OFFBOARD): the sticks
  count as moving when one moves faster than ``COM_RC_STICK_OV`` percent per second (30).
  By default OFFBOARD stays (seen on 1.17.0); with bit 1 set Position takes over (seen on
  1.17.0 with ``COM_RC_OVERRIDE`` 3, ``corpora/sitl/sticks_moved_override-1.17.0``). 1.14-1.16
  follow the same parameters, not run with a joystick ramp.
* Older releases: not modelled.

PX4 low-pass filters the stick speed before comparing it; the filter's constant is not modelled:
the model takes the mean speed of the three same-direction samples, which a steady ramp
reaches and a step or a swing never satisfies. Where the recording logs PX4's own
``sticks_moving`` (a ULog) that verdict is used instead.
"""

from __future__ import annotations

import math
from dataclasses import field

from fuzzoff.events import NAV_STATE_OFFBOARD, ManualControl
from fuzzoff.gate.effective import EffectiveMode
from fuzzoff.gate.state import GateState
from fuzzoff.lean_dataclass import dataclass

NAV_STATE_POSCTL = 2
SAME_DIRECTION_SAMPLES = 3
"""Samples in a row one stick must move the same way (1.18+)."""
AXES = ("roll", "pitch", "yaw", "throttle")
ROTARY_WING = ("mc", "vtol")
"""The vehicle types whose sticks take over (VTOL modelled in hover, as its controllers)."""


@dataclass(slots=True)
class _Axis:
    value: float | None = None
    t: float = 0.0
    run: list[float] = field(default_factory=list)
    """The speeds of the current run of same-direction samples, newest last."""

    def update(self, t: float, value: float) -> float | None:
        """The speed since the previous sample, and the run it extends."""
        previous, since = self.value, self.t
        self.value, self.t = value, t
        if previous is None or not math.isfinite(value) or not math.isfinite(previous):
            self.run.clear()
            return None
        dt = t - since
        if dt <= 0:
            return None
        speed = (value - previous) / dt
        if speed == 0 or (self.run and (speed > 0) != (self.run[-1] > 0)):
            self.run.clear()
        if speed != 0:
            self.run.append(speed)
            del self.run[:-SAME_DIRECTION_SAMPLES]
        return speed


def override_threshold(state: GateState) -> tuple[float, str] | None:
    """The stick speed (per second) that takes over OFFBOARD and the parameter that set it;
    None where the sticks do not end OFFBOARD on this release and configuration."""
    kind = state.release.stick_override
    params = state.params
    if kind == "man_override_spd":
        speed = float(params.get("MAN_OVERRIDE_SPD", 1.0))
        return None if speed < 0 else (speed, f"MAN_OVERRIDE_SPD {speed:g}")
    if kind == "com_rc_override":
        bits = params.get("COM_RC_OVERRIDE", 1.0)
        if not math.isfinite(bits) or not int(bits) & 2:
            return None
        percent = float(params.get("COM_RC_STICK_OV", 30.0))
        return percent / 100.0, f"COM_RC_OVERRIDE {int(bits)}, COM_RC_STICK_OV {percent:g} %"
    return None


class StickOverride:
    def __init__(self, state: GateState, mode: EffectiveMode) -> None:
        self.s = state
        self.mode = mode
        self.axes = {name: _Axis() for name in AXES}

    def moving(self, e: ManualControl, threshold: float) -> bool:
        """Do the sticks count as moving at this sample (PX4's ``sticks_moving``)?"""
        runs = []
        for name, axis in self.axes.items():
            speed = axis.update(e.t, getattr(e, name))
            if speed is not None:
                runs.append(axis.run)
        if e.sticks_moving is not None:
            return e.sticks_moving
        if self.s.release.stick_override == "com_rc_override":
            return any(abs(run[-1]) > threshold for run in runs if run)
        return any(
            len(run) >= SAME_DIRECTION_SAMPLES and abs(sum(run)) / len(run) > threshold
            for run in runs
        )

    def manual_control(self, e: ManualControl) -> bool:
        s = self.s
        found = override_threshold(s)
        threshold = found[0] if found is not None else math.inf
        if not self.moving(e, threshold) or found is None:
            return False
        if s.vehicle_type not in ROTARY_WING or s.armed is not True:
            return False
        if s.user_intention != NAV_STATE_OFFBOARD or s.fallback is not None:
            return False
        s.user_intention = NAV_STATE_POSCTL
        s.fallback_stage = 0
        s.emit(
            e.t,
            "mode",
            f"sticks moved in OFFBOARD ({found[1]}): Position takes over, OFFBOARD does not "
            "come back by itself",
            "16",
            nav_state=NAV_STATE_POSCTL,
            reason="stick override",
        )
        self.mode.refresh(e.t, cause=None)
        return True
