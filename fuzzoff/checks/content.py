"""OFB401-OFB403, OFB405-OFB408: what the setpoint messages carry.

Seed 000 "Мультикоптери" and "Універсальний апарат" (002 "旋翼机", "Generic Vehicle"); the
per-axis validity of OFB403 is the code's rule (gate.md#multicopter, #docs-vs-code).
OFB405/OFB406 also
judge MAVLink ``SET_ATTITUDE_TARGET`` where its ``type_mask`` uses the field.
"""

from __future__ import annotations

import math
from itertools import chain, repeat
from operator import attrgetter, mul, sub
from typing import Any, cast

from fuzzoff.checks._external import Episodes, external_only, from_external, is_armed
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import (
    ActuatorMotors,
    ActuatorServos,
    AttitudeSetpoint,
    Event,
    RatesSetpoint,
    SetAttitudeTarget,
    ThrustSetpoint,
    TorqueSetpoint,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.findings import clip
from fuzzoff.tables.control_mode import SETPOINT_NAMES
from fuzzoff.type_mask import ATTITUDE_IGNORE, THROTTLE_IGNORE, THRUST_BODY_SET

TRAJECTORY_CONTROLS = ("position", "velocity", "acceleration")

MAVLINK_THRUST_RANGE: dict[str, tuple[float, float]] = {"mc": (0.0, 1.0), "vtol": (0.0, 1.0)}
"""SET_ATTITUDE_TARGET ``thrust``: 0..1, -1..1 where the vehicle can reverse (fw, rovers)."""

_TRAJECTORY: tuple[type[Event], ...] = (TrajectorySetpoint,)
_ATTITUDE: tuple[type[Event], ...] = (AttitudeSetpoint,)
_SET_ATTITUDE: tuple[type[Event], ...] = (SetAttitudeTarget,)
_MOTORS: tuple[type[Event], ...] = (ActuatorMotors,)
_RATES_SETPOINT: tuple[type[Event], ...] = (RatesSetpoint,)
_Q_D = attrgetter("q_d")
_XYZ = attrgetter("xyz")
_CONTROL = attrgetter("control")
_RATES = attrgetter("roll", "pitch", "yaw")
_THRUST_BODY = attrgetter("thrust_body")


def _all_unit(quaternions: list[tuple[float, ...]], tolerance: float) -> bool:
    """Every norm within ``tolerance`` of 1: the norms are ``QuaternionNotUnit``'s own
    expression (the same products summed in the same order), so the verdict is exact."""
    norms = map(math.sqrt, map(sum, map(map, repeat(mul), quaternions, quaternions)))
    return math.isfinite(tolerance) and all(
        map(tolerance.__ge__, map(abs, map(sub, norms, repeat(1.0))))
    )


def _within(values: list[tuple[float, ...]], low: float, high: float) -> bool:
    """No finite value outside [low, high] (NaN never wins a ``max``/``min`` started from a
    number; an infinity fails the test and is judged one by one)."""
    flat = list(chain.from_iterable(values))
    return max(chain((low,), flat)) <= high and min(chain((high,), flat)) >= low


def _nan_pattern(motors: ActuatorMotors) -> tuple[tuple[bool, ...], tuple[bool, ...]]:
    """Which controls are NaN and which finite: all that OFB407 reads of a message."""
    control = motors.control
    return tuple(map(math.isnan, control)), tuple(map(math.isfinite, control))


def finiteness(sp: TrajectorySetpoint) -> tuple[tuple[bool, bool, bool], ...]:
    """Which components of position, velocity and acceleration are finite (computed once)."""
    isf = math.isfinite
    p, v, a = sp.position, sp.velocity, sp.acceleration
    # spelled out rather than a generator: once per TrajectorySetpoint (saves ~0.5 µs)
    return (
        (isf(p[0]), isf(p[1]), isf(p[2])),
        (isf(v[0]), isf(v[1]), isf(v[2])),
        (isf(a[0]), isf(a[1]), isf(a[2])),
    )


def content_controller(sp: TrajectorySetpoint) -> str | None:
    """The controller the docs say the content selects (seed 000 "Мультикоптери")."""
    return _selected(finiteness(sp))


def _selected(finite: tuple[tuple[bool, bool, bool], ...]) -> str | None:
    for name, components in zip(TRAJECTORY_CONTROLS, finite, strict=True):
        if any(components):
            return name
    return None


def axis_problems(sp: TrajectorySetpoint) -> list[str]:
    """What PX4's position controller rejects (gate.md#multicopter, ``_inputValid``)."""
    return _axis_problems(finiteness(sp))


def _axis_problems(finite: tuple[tuple[bool, bool, bool], ...]) -> list[str]:
    (px, py, pz), (vx, vy, vz), (ax, ay, az) = finite
    every_axis = (px or vx or ax) and (py or vy or ay) and (pz or vz or az)
    if every_axis and px == py and vx == vy and ax == ay:
        return []  # the usual valid setpoint, without building the lists below
    problems = []
    for i, axis in enumerate("xyz"):
        if not (finite[0][i] or finite[1][i] or finite[2][i]):
            problems.append(f"axis {axis} has no finite position, velocity or acceleration")
    for name, (fx, fy, _) in zip(TRAJECTORY_CONTROLS, finite, strict=True):
        if fx != fy:
            problems.append(f"{name} x and y are not both finite or both NaN")
    return problems


class TrajectoryContent(Check):
    """OFB401 (controller mismatch), OFB402 (all NaN), OFB403 (axis invalid)."""

    codes = ("OFB401", "OFB402", "OFB403")
    wants = (TrajectorySetpoint,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.mismatch = Episodes(ctx, "OFB401")
        self.all_nan = Episodes(ctx, "OFB402")
        self.axis = Episodes(ctx, "OFB403")
        self.vehicle = ctx.profile.vehicle

    @property
    def multicopter(self) -> bool:
        """Flying as a multicopter now: a VTOL by its recorded phase (in FW flight PX4's
        fixed-wing controllers take the setpoint, not the multicopter position controller)."""
        if self.vehicle == "vtol":
            return self.ctx.state.vtol_phase != "fw"
        return self.vehicle == "mc"

    def on_event(self, event: Event) -> None:
        assert isinstance(event, TrajectorySetpoint)
        flag = self.ctx.state.declared_flag  # declared_flag(ctx), without the call
        if flag not in TRAJECTORY_CONTROLS or not from_external(self.ctx, event):
            return
        finite = finiteness(event)
        selected = _selected(finite)
        if selected is None:
            self.all_nan.bad(
                "nan",
                event.t,
                event.where,
                f"TrajectorySetpoint with position, velocity and acceleration all NaN while "
                f"OffboardControlMode declares '{flag}': it sets no target",
                short=f"TrajectorySetpoint all NaN under '{flag}': no target",
            )
            return
        self.all_nan.good("nan")
        if selected != flag:
            self.mismatch.bad(
                f"{flag}/{selected}",
                event.t,
                event.where,
                f"OffboardControlMode declares '{flag}' but the TrajectorySetpoint content "
                f"selects the {selected} controller; PX4 follows the content",
                short=f"'{flag}' declared, but the setpoint's content flies {selected} control",
            )
        else:
            self.mismatch.close_all()
        problems = _axis_problems(finite) if self.multicopter else []
        if problems:
            self.axis.bad(
                "axis",
                event.t,
                event.where,
                f"TrajectorySetpoint PX4's position controller rejects: {'; '.join(problems)}; "
                f"{_invalid_effect(self.ctx)}",
                short=clip(f"TrajectorySetpoint rejected by PX4: {problems[0]}"),
            )
        else:
            self.axis.good("axis")

    def on_batch(self, batch: StreamBatch) -> None:
        """Within a run the declared flag and the mode are fixed, so an external setpoint's
        verdict depends only on which components are finite (the others are not judged). When
        every external setpoint of the run has the same, the first is judged by ``on_event``
        and the rest only extend the episodes it left open (a clean run with nothing open
        costs nothing more)."""
        flag = batch.state.declared_flag
        if flag not in TRAJECTORY_CONTROLS:
            return
        events = external_only(self.ctx, batch.of(_TRAJECTORY))
        if not events:
            return
        keys = set(map(finiteness, cast(list[TrajectorySetpoint], events)))
        if len(keys) > 1:
            self.replay(batch)
            return
        bad = self._bad_keys(flag, keys.pop())
        if not bad and not (self.mismatch.open or self.all_nan.open or self.axis.open):
            return
        self.on_event(events[0])
        if len(events) > 1:
            for episodes, key in bad:
                episodes.extend(key, events[-1].t, len(events) - 1)

    def _bad_keys(
        self, flag: str, finite: tuple[tuple[bool, bool, bool], ...]
    ) -> list[tuple[Episodes, str]]:
        """The episodes ``on_event`` extends for a setpoint of this finiteness."""
        selected = _selected(finite)
        if selected is None:
            return [(self.all_nan, "nan")]
        bad = []
        if selected != flag:
            bad.append((self.mismatch, f"{flag}/{selected}"))
        if self.multicopter and _axis_problems(finite):
            bad.append((self.axis, "axis"))
        return bad

    def finish(self, t_end: float) -> None:
        for episodes in (self.mismatch, self.all_nan, self.axis):
            episodes.close_all()


def _invalid_effect(ctx: CheckContext) -> str:
    """What mc_pos_control does with invalid input (gate.md#multicopter)."""
    if ctx.profile.release.reuses_last_valid_setpoint:
        return (
            f"PX4 {ctx.profile.px4} reuses the last valid setpoint for 200 ms, then flies a "
            "failsafe setpoint (hold, or descend without a velocity estimate)"
        )
    return (
        f"PX4 {ctx.profile.px4} flies a failsafe setpoint at once (hold, or descend without "
        "a velocity estimate)"
    )


class QuaternionNotUnit(Check):
    """OFB405: ``q_d`` / ``SET_ATTITUDE_TARGET.q`` NaN or off unit norm, where it is used."""

    codes = ("OFB405",)
    wants = (AttitudeSetpoint, SetAttitudeTarget)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.tolerance = float(ctx.option("OFB405", "tolerance"))
        self.episodes = Episodes(ctx, "OFB405")

    def on_event(self, event: Event) -> None:
        if isinstance(event, AttitudeSetpoint):
            if not from_external(self.ctx, event):
                return
            q, name = event.q_d, "VehicleAttitudeSetpoint.q_d"
        elif isinstance(event, SetAttitudeTarget):
            if event.type_mask & ATTITUDE_IGNORE:
                self.episodes.good(event.kind)
                return
            q, name = event.q, "SET_ATTITUDE_TARGET.q"
        else:
            return
        norm = math.sqrt(sum(v * v for v in q))
        if math.isfinite(norm) and abs(norm - 1.0) <= self.tolerance:
            self.episodes.good(event.kind)
            return
        what = "contains NaN" if not math.isfinite(norm) else f"has norm {norm:.4f}"
        self.episodes.bad(
            event.kind,
            event.t,
            event.where,
            f"{name} {what}: not a unit quaternion (tolerance {self.tolerance:g}); PX4 uses "
            f"it as is",
        )

    def on_batch(self, batch: StreamBatch) -> None:
        """Nothing open and every quaternion used a unit one: every message is clean and
        changes nothing. Otherwise replayed."""
        attitude = batch.of(_ATTITUDE)
        mavlink = batch.of(_SET_ATTITUDE)
        if not (attitude or mavlink):
            return
        if self.episodes.open:
            self.replay(batch)
            return
        quaternions: list[tuple[float, ...]] = list(map(_Q_D, external_only(self.ctx, attitude)))
        if mavlink:
            targets = cast(list[SetAttitudeTarget], mavlink)
            quaternions.extend(e.q for e in targets if not e.type_mask & ATTITUDE_IGNORE)
        if not _all_unit(quaternions, self.tolerance):
            self.replay(batch)

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()


class NormalizedOutOfRange(Check):
    """OFB406: a value the docs normalise to [-1, 1] outside it."""

    codes = ("OFB406",)
    wants = (
        AttitudeSetpoint,
        RatesSetpoint,
        ThrustSetpoint,
        TorqueSetpoint,
        ActuatorMotors,
        ActuatorServos,
        SetAttitudeTarget,
    )

    FIELDS: tuple[tuple[tuple[type[Event], ...], attrgetter[Any]], ...] = (
        ((AttitudeSetpoint, RatesSetpoint), _THRUST_BODY),
        ((ThrustSetpoint, TorqueSetpoint), _XYZ),
        ((ActuatorMotors, ActuatorServos), _CONTROL),
    )
    """The PX4 setpoints judged, and the field in [-1, 1] (as in ``_values``)."""
    PX4_TYPES = tuple(cls for classes, _ in FIELDS for cls in classes)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB406")

    def _values(self, event: Event) -> tuple[str, tuple[float, ...], tuple[float, float]] | None:
        unit = (-1.0, 1.0)
        if isinstance(event, SetAttitudeTarget):
            if event.type_mask & THRUST_BODY_SET and event.thrust_body is not None:
                return "SET_ATTITUDE_TARGET.thrust_body", event.thrust_body, unit
            if event.type_mask & THROTTLE_IGNORE:
                return None
            span = MAVLINK_THRUST_RANGE.get(self.ctx.profile.vehicle, unit)
            return "SET_ATTITUDE_TARGET.thrust", (event.thrust,), span
        if not from_external(self.ctx, event):
            return None
        name = SETPOINT_NAMES[event.kind]
        if isinstance(event, (AttitudeSetpoint, RatesSetpoint)):
            return f"{name}.thrust_body", event.thrust_body, unit
        if isinstance(event, (ThrustSetpoint, TorqueSetpoint)):
            return f"{name}.xyz", event.xyz, unit
        if isinstance(event, (ActuatorMotors, ActuatorServos)):
            return f"{name}.control", event.control, unit
        return None

    def on_event(self, event: Event) -> None:
        found = self._values(event)
        if found is None:
            return
        name, values, (low, high) = found
        bad = [(i, v) for i, v in enumerate(values) if math.isfinite(v) and not low <= v <= high]
        if not bad:
            self.episodes.good(event.kind)
            return
        shown = ", ".join(f"[{i}] = {v:g}" for i, v in bad)
        self.episodes.bad(
            event.kind,
            event.t,
            event.where,
            f"{name} outside [{low:g}, {high:g}]: {shown}",
        )

    def on_batch(self, batch: StreamBatch) -> None:
        """Nothing open, PX4 setpoints only (``SET_ATTITUDE_TARGET`` depends on each mask:
        replayed), and no finite value outside [-1, 1]: every message is clean and changes
        nothing. Otherwise replayed."""
        present = batch.classes()
        if present.isdisjoint(self.PX4_TYPES):
            if SetAttitudeTarget in present:
                self.replay(batch)
            return
        if SetAttitudeTarget in present or self.episodes.open:
            self.replay(batch)
            return
        values: list[tuple[float, ...]] = []
        for classes, field in self.FIELDS:
            values.extend(map(field, external_only(self.ctx, batch.of(classes))))
        if values and not _within(values, -1.0, 1.0):
            self.replay(batch)

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()


class ActuatorNanDisarms(Check):
    """OFB407: NaN in an ``ActuatorMotors`` control while armed disarms that motor.

    Trailing NaNs after the last finite motor are unused outputs and stay clean, unless that
    motor was commanded earlier while armed.
    """

    codes = ("OFB407",)
    wants = (ActuatorMotors, VehicleStatus)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB407")
        self.active: set[int] = set()
        self.saw_motors = False

    def on_event(self, event: Event) -> None:
        self.saw_motors = self.saw_motors or isinstance(event, ActuatorMotors)
        if not is_armed(self.ctx):
            self.active.clear()
            self.episodes.close_all()
            return
        if not isinstance(event, ActuatorMotors) or not from_external(self.ctx, event):
            return
        finite = [i for i, v in enumerate(event.control) if math.isfinite(v)]
        last = max(finite, default=-1)
        nan = [
            i
            for i, v in enumerate(event.control)
            if math.isnan(v) and (i < last or i in self.active)
        ]
        self.active.update(finite)
        if not nan:
            self.episodes.good("nan")
            return
        self.episodes.bad(
            "nan",
            event.t,
            event.where,
            f"ActuatorMotors.control NaN at {', '.join(f'[{i}]' for i in nan)} while armed: "
            "PX4 disarms that motor output",
        )

    def on_batch(self, batch: StreamBatch) -> None:
        """Arming and the mode are fixed within a run. When every message has the same NaN
        pattern, each reports the same indices (``active`` only gains finite ones, which are
        never NaN in this pattern): the first is judged, the rest extend its episode."""
        motors = batch.of(_MOTORS)
        if not motors:
            return
        self.saw_motors = True
        if not is_armed(self.ctx):
            self.active.clear()
            self.episodes.close_all()
            return
        motors = external_only(self.ctx, motors)
        if not motors:
            return
        if len(set(map(_nan_pattern, cast(list[ActuatorMotors], motors)))) > 1:
            self.replay(batch)
            return
        self.on_event(motors[0])
        if len(motors) > 1 and "nan" in self.episodes.open:
            self.episodes.extend("nan", motors[-1].t, len(motors) - 1)

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()
        if self.saw_motors and not self.ctx.has("vehicle_status", "command"):
            self.ctx.cannot_check(
                "OFB407", "needs the arming state (vehicle_status, or the arm commands)"
            )


class RatesIncomplete(Check):
    """OFB408: ``VehicleRatesSetpoint`` needs roll, pitch, yaw and thrust_body."""

    codes = ("OFB408",)
    wants = (RatesSetpoint,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx, "OFB408")

    def on_event(self, event: Event) -> None:
        assert isinstance(event, RatesSetpoint)
        if not from_external(self.ctx, event):
            return
        values = {
            "roll": event.roll,
            "pitch": event.pitch,
            "yaw": event.yaw,
            **{f"thrust_body[{i}]": v for i, v in enumerate(event.thrust_body)},
        }
        missing = [name for name, v in values.items() if math.isnan(v)]
        if not missing:
            self.episodes.good("nan")
            return
        self.episodes.bad(
            "nan",
            event.t,
            event.where,
            f"VehicleRatesSetpoint with NaN in {', '.join(missing)}: the docs require roll, "
            "pitch, yaw and thrust_body",
        )

    def on_batch(self, batch: StreamBatch) -> None:
        """No NaN in any field of the run (their sum is not NaN) and nothing open: every
        message is clean and changes nothing. Otherwise replayed."""
        rates = batch.of(_RATES_SETPOINT)
        if not rates:
            return
        if self.episodes.open:
            self.replay(batch)
            return
        rates = external_only(self.ctx, rates)
        if not rates:
            return
        total = sum(map(sum, map(_RATES, rates))) + sum(map(sum, map(_THRUST_BODY, rates)))
        if math.isnan(total):
            self.replay(batch)

    def finish(self, t_end: float) -> None:
        self.episodes.close_all()
