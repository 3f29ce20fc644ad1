"""OFB601-OFB605: the fields of SET_POSITION_TARGET_LOCAL_NED / _GLOBAL_INT against the docs.

Seed 000 "MAVLink Offboard Control" (1.15+) and seed 002 "MAVLink 消息" (1.13-1.14) list, per
vehicle type, the supported ``coordinate_frame`` values and ``type_mask`` combinations; the
tables are in ``fuzzoff.tables.mavlink``. Every setpoint the recording shows on its way to the
vehicle is judged, in any mode: a message PX4 drops is also a keep-alive that never counted.

OFB609 covers PX4 legacy and 1.11, which no seed documents field by field: it follows the legacy
receiver (gate.md#receiver) and reports what it drops or does not forward.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from itertools import chain
from operator import attrgetter
from typing import Any

from fuzzoff import type_mask as tmask
from fuzzoff.checks._episodes import Episodes, Offence
from fuzzoff.checks._runs import Verdicts, commit_alike, first_of_each, sent_only
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.checks.content import _axis_problems
from fuzzoff.events import (
    Event,
    SetAttitudeTarget,
    SetPositionTargetGlobal,
    SetPositionTargetLocal,
)
from fuzzoff.findings import Severity, clip
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.receiver import DROPPED, FLOAT_FIELDS, ReceiverContext, receive
from fuzzoff.tables import mavlink as tm

VEHICLE_LABELS = {"copter": "multicopter/VTOL", "fixedwing": "fixed-wing", "rover": "rover"}

PositionTarget = SetPositionTargetLocal | SetPositionTargetGlobal

GLOBAL_POSITION_FIELDS = (
    ("lat_int", tmask.X_IGNORE),
    ("lon_int", tmask.Y_IGNORE),
    ("alt", tmask.Z_IGNORE),
)
"""The position fields of SET_POSITION_TARGET_GLOBAL_INT and their ignore bits."""

_MASK_KEY = attrgetter("kind", "type_mask")
_KEY = attrgetter(
    "origin", "kind", "type_mask", "coordinate_frame", "target_system", "target_component"
)
"""Whether ``on_event`` judges the message (origin) and, besides which float fields are finite,
everything ``receive`` reads from a position target; the rest of the verdicts read only kind,
type_mask and coordinate_frame."""

_FLOATS: dict[type, tuple[tuple[Callable[[Event], Any], ...], ...]] = {
    cls: (tuple(map(attrgetter, vectors)), tuple(map(attrgetter, values)))
    for cls, (vectors, values) in FLOAT_FIELDS.items()
}
"""The float fields ``receive`` classifies (``FLOAT_FIELDS``), as getters."""


def all_finite(events: list[Event]) -> bool:
    """Is every float field of every message (``_FLOATS``: all that the receivers read) finite?

    A sum is finite only if every term is (an overflow, or a value that is not a number, only
    fails the proof); with every value finite, ``receive`` gives the same answer for messages
    with the same ``_KEY``."""
    types = set(map(type, events))
    try:
        for cls in types:
            group = events if len(types) == 1 else [e for e in events if type(e) is cls]
            vectors, values = _FLOATS[cls]
            total = 0.0
            for read in vectors:
                total += sum(chain.from_iterable(map(read, group)))
            for read in values:
                total += sum(map(read, group))
            if not math.isfinite(total):
                return False
    except (TypeError, OverflowError):
        return False
    return True


def frames_text(frames: frozenset[int]) -> str:
    return ", ".join(f"{tm.frame_name(f)} ({f})" for f in sorted(frames))


def set_components(event: PositionTarget, group: str) -> list[str]:
    """Components of ``group`` that are used (ignore bit clear) and carry a non-zero value."""
    names = {"velocity": ("vx", "vy", "vz"), "acceleration": ("afx", "afy", "afz")}[group]
    values = event.velocity if group == "velocity" else event.acceleration
    first_bit = 8 if group == "velocity" else 64
    out = []
    for i, (name, value) in enumerate(zip(names, values, strict=True)):
        ignored = event.type_mask & (first_bit << i)
        if not ignored and value != 0 and not math.isnan(value):
            out.append(name)
    return out


ACTION_TYPES = {"takeoff": "takeoff", "land": "landing", "idle": "idle throttle"}
"""The fixed-wing setpoint types that ask for an action PX4 (1.12+) does not take (OFB603)."""


class PositionTargetFields(Check):
    codes = ("OFB601", "OFB602", "OFB603", "OFB604", "OFB605")
    wants = (SetPositionTargetLocal, SetPositionTargetGlobal)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.group = tm.vehicle_group(ctx.profile.vehicle)
        self.vehicle_label = VEHICLE_LABELS[self.group]
        self.by_mask: dict[tuple[str, int, int], list[tuple[str, dict[str, Offence]]]] = {}
        """Verdicts by (message, type_mask, frame): a stream repeats the same few."""
        self.stream_types = self.wants
        self.by_key: dict[tuple[object, ...], Verdicts] = {}
        """What a message commits by ``_KEY``, with every float finite (runs only)."""
        self.est_seen: Estimates | None = None
        """The receiver's estimates ``by_key`` was worked out with (a copy)."""
        self.rx: ReceiverContext | None = None
        """PX4's receiver, to see the axes a copter setpoint leaves (1.13+: a docs page)."""
        if self.group == "copter" and tm.page_for(ctx.profile) is not None:
            self.rx = ReceiverContext(
                release=ctx.profile.release,
                own_system=None,
                own_component=int(ctx.gate.params.get("MAV_COMP_ID", 1.0)),
                fwdextsp=True,
                est=ctx.gate.est,
            )

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: the verdicts depend on the message only through ``_KEY`` (and, for the
        receiver's axes, on every float field being finite, ``all_finite``). With no offence and
        nothing open, nothing happens; with one key, every message commits the same offences
        and (gaps under ``MERGE_GAP_S``) only extends the stretches the first one opened."""
        events = sent_only(batch.of(self.stream_types))  # on_event judges only these
        if not events:
            return
        verdicts = self._verdicts_by_key(events)
        if verdicts is None or not commit_alike(self.episodes, events[0].kind, events, verdicts):
            self.replay(batch)

    def _verdicts_by_key(self, events: list[Event]) -> list[Verdicts] | None:
        """What a message of each ``_KEY`` of the run commits, or None where that needs each
        message (fixed-wing ignored fields, a non-finite value for the axes)."""
        if self.group == "fixedwing" or self.ctx.state.vtol_phase is not None:
            return None  # a VTOL: per message, as its phase says (``_copter_axes``)
        if self.group == "copter" and self.rx is not None:
            if not all_finite(events):
                return None
            if self.rx.est != self.est_seen:  # the answers below hold for these estimates
                self.by_key.clear()
                self.est_seen = copy.copy(self.rx.est)
        first = first_of_each(_KEY, events)
        if len(first) == 1:
            ((key, event),) = first.items()
            verdicts = self.by_key.get(key)
            if verdicts is None:
                verdicts = self.by_key[key] = self._verdicts(event)
            return [verdicts]
        return [self._verdicts(event) for event in first.values()]

    def _verdicts(self, event: Event) -> Verdicts:
        """What ``on_event`` commits for this message (all but the fixed-wing part)."""
        assert isinstance(event, (SetPositionTargetLocal, SetPositionTargetGlobal))
        key = (event.kind, event.type_mask, event.coordinate_frame)
        judged = self.by_mask.get(key)
        if judged is None:
            judged = self.by_mask[key] = self._judge_mask(event)
        if self._copter_axes() and self.rx is not None:
            return [*judged, ("OFB602", self._mc_axes(event, self.rx))]
        return judged

    def _copter_axes(self) -> bool:
        """Does PX4's multicopter position controller take the setpoint now? Not a VTOL's in
        FW flight, on any release: there the fixed-wing controllers do. Seen on the standard
        VTOL in FW flight with z NaN (type_mask 292): 1.18 glides (``vtol_fw_glide-*``,
        ``vtol_fw_types-1.18.0-beta1-head``), 1.17.0 flew on at its altitude toward x, y
        (``vtol_fw_types-1.17.0``); neither held as a multicopter would."""
        if self.group != "copter":
            return False
        return self.ctx.state.vtol_phase != "fw"

    def on_event(self, event: Event) -> None:
        if event.origin != "sent" or not isinstance(
            event, (SetPositionTargetLocal, SetPositionTargetGlobal)
        ):
            return
        key = (event.kind, event.type_mask, event.coordinate_frame)
        judged = self.by_mask.get(key)
        if judged is None:
            judged = self.by_mask[key] = self._judge_mask(event)
        for code, offences in judged:
            self.episodes.update(code, event.kind, event.t, event.where, offences)
        if self._copter_axes() and self.rx is not None:
            offences = self._mc_axes(event, self.rx)
            self.episodes.update("OFB602", event.kind, event.t, event.where, offences)
        rules = self._fw_rules(event.kind)
        if rules is not None:
            name = tm.MESSAGE_NAMES[event.kind]
            offences = self._fw_ignored(event, name, rules)
            self.episodes.update("OFB604", event.kind, event.t, event.where, offences)

    def _fw_rules(self, kind: str) -> tm.PositionTargetRules | None:
        """The docs' fixed-wing table, where a fixed wing takes the setpoint: an airplane, or a
        VTOL in FW flight (its fixed-wing controllers fly it; seen on the standard VTOL,
        ``vtol_fw_velocity-*``). None where no docs page covers the release."""
        in_fw = self.group == "fixedwing" or (
            self.group == "copter" and self.ctx.state.vtol_phase == "fw"
        )
        page = tm.page_for(self.ctx.profile) if in_fw else None
        return None if page is None else page.position_rules(kind, "fixedwing")

    def _judge_mask(self, event: PositionTarget) -> list[tuple[str, dict[str, Offence]]]:
        """The verdicts that depend only on the message, its type_mask and its frame."""
        name = tm.MESSAGE_NAMES[event.kind]
        out = [("OFB603", self._setpoint_type(event, name))]
        rules = tm.position_rules(self.ctx.profile, event.kind)
        if rules is None:
            return out
        usable = tm.selected_groups(event.type_mask) - rules.ignored
        out.append(("OFB601", self._frame(event, name, rules, usable)))
        out.append(("OFB602", self._combo(event, name, rules)))
        out.append(("OFB605", self._global_accel(event)))
        return out

    # -- OFB601 -------------------------------------------------------------------------

    def _frame(
        self,
        event: PositionTarget,
        name: str,
        rules: tm.PositionTargetRules,
        usable: tm.Combo,
    ) -> dict[str, Offence]:
        frame = event.coordinate_frame
        docs = rules.frames_for(usable)
        receiver = tm.RECEIVER_FRAMES[event.kind]
        px4 = self.ctx.profile.px4
        what = f"{name} with coordinate_frame {tm.frame_name(frame)} ({frame})"
        brief = f"coordinate_frame {tm.frame_name(frame)} ({frame})"
        if frame in docs:
            if frame in receiver:
                return {}
            return {
                f"frame:{frame}": Offence(
                    f"{what}: listed by the PX4 {px4} docs, but PX4's receiver accepts only "
                    f"{frames_text(receiver)} and drops the message (no setpoint, no keep-alive)",
                    short=f"{brief}: in the docs, but PX4 drops it",
                )
            }
        for_what = f"a {tm.describe_combo(usable)} setpoint" if usable in rules.combos else name
        docs_text = (
            f"the PX4 {px4} docs support only {frames_text(docs)} for {for_what} on a "
            f"{self.vehicle_label}"
        )
        # In BODY_NED the receiver always drops the position (gate.md#receiver).
        body_position = event.kind == tm.LOCAL and frame == 8 and "position" in usable
        if frame in receiver and not body_position:
            return {
                f"frame:{frame}": Offence(
                    f"{what}: {docs_text}; PX4's receiver accepts it nevertheless (every "
                    "release from v1.12)",
                    Severity.INFO,
                    f"{brief}: not in the docs, but PX4 takes it",
                )
            }
        consequence = "PX4 drops the message (no setpoint, no keep-alive)"
        if body_position and frame in receiver:
            if tm.body_ned_groups(event.type_mask):
                consequence = "PX4 ignores the position in this frame"
            else:
                consequence = (
                    "PX4 ignores the position in this frame and, with nothing else left, "
                    "drops the message (no setpoint, no keep-alive)"
                )
        dropped = "drops" in consequence
        short = f"{brief}: {'dropped, no keep-alive' if dropped else 'position ignored'}"
        return {f"frame:{frame}": Offence(f"{what}: {docs_text}; {consequence}", short=short)}

    # -- OFB602 -------------------------------------------------------------------------

    def _combo(
        self, event: PositionTarget, name: str, rules: tm.PositionTargetRules
    ) -> dict[str, Offence]:
        mask = event.type_mask
        selected = tm.selected_groups(mask)
        head = f"{name} type_mask {mask}"
        if not selected:
            return {
                "empty": Offence(
                    f"{head} selects no position, velocity or acceleration: PX4 drops it "
                    "(no setpoint, no keep-alive)",
                    short=f"type_mask {mask} selects nothing: dropped, no keep-alive",
                )
            }
        if mask & tmask.FORCE_SET and "acceleration" in selected:
            return {
                "force": Offence(
                    f"{head} sets the FORCE bit: force setpoints are not supported and PX4 "
                    "drops the message (no setpoint, no keep-alive)"
                )
            }
        partial = self._global_partial_position(event, head, selected)
        if partial is not None:
            return partial
        usable = selected - rules.ignored
        body = self._body_ned_drop(event, head, rules, selected, usable)
        if body is not None:
            return body
        if not usable or usable in rules.combos:
            return {}
        supported = "; ".join(tm.describe_combo(c) for c in rules.combos)
        if self.group == "copter":
            # the position controller flies any mix whose axes are valid (the axes rule below
            # says when they are not): the docs' list alone, which no release enforces
            px4_does = "PX4's receiver passes it on and the position controller flies it per axis"
            severity = Severity.INFO
        else:
            px4_does = (
                "PX4's receiver passes it on; what the rover or fixed-wing controllers make of "
                "the mix is unverified"
            )
            severity = Severity.WARNING
        return {
            f"combo:{tm.describe_combo(usable)}": Offence(
                f"{head} selects {tm.describe_combo(usable)}, not a combination the PX4 "
                f"{self.ctx.profile.px4} docs support on a {self.vehicle_label} (supported: "
                f"{supported}); {px4_does}",
                severity,
                short=f"type_mask {event.type_mask} selects {tm.describe_combo(usable)}: not in "
                f"the docs' list for a {self.vehicle_label}",
            )
        }

    def _global_partial_position(
        self, event: PositionTarget, head: str, selected: tm.Combo
    ) -> dict[str, Offence] | None:
        """GLOBAL_INT (gate.md#receiver): the receiver takes the position only whole; an ignore bit
        on any of lat, lon or alt drops all three. With no velocity or acceleration left the
        message is dropped silently (no setpoint, no keep-alive); otherwise only the rest is
        flown. The legacy and 1.11 handlers are OFB609's."""
        mask = event.type_mask
        if event.kind != tm.GLOBAL or not mask & tmask.POSITION_BITS or "position" not in selected:
            return None
        ignored = [name for name, bit in GLOBAL_POSITION_FIELDS if mask & bit]
        used = [name for name, bit in GLOBAL_POSITION_FIELDS if not mask & bit]
        rest = selected - {"position"}
        why = (
            f"{head} uses {' and '.join(used)} but ignores {' and '.join(ignored)}: PX4's "
            "receiver takes this message's position only whole (lat, lon and alt) and so "
            "ignores all of it"
        )
        if rest:
            return {
                "global_partial": Offence(
                    f"{why}, so the vehicle flies the {tm.describe_combo(rest)} alone and never "
                    "goes to the position sent (to hold an altitude while moving, send the whole "
                    "position, or use SET_POSITION_TARGET_LOCAL_NED, whose axes are taken one by "
                    "one)",
                    short=f"type_mask {mask}: part of the position ignored, so all of it: "
                    f"{tm.describe_combo(rest)} only",
                )
            }
        yaw = "" if mask & tmask.YAW_IGNORE and mask & tmask.YAW_RATE_IGNORE else " (yaw alone)"
        return {
            "global_partial": Offence(
                f"{why}; with no velocity or acceleration left{yaw} PX4 drops the message "
                "silently (no setpoint, no keep-alive); send the whole position",
                short=f"type_mask {mask}: part of the position ignored: dropped, no keep-alive",
            )
        }

    def _body_ned_drop(
        self,
        event: PositionTarget,
        head: str,
        rules: tm.PositionTargetRules,
        selected: tm.Combo,
        usable: tm.Combo,
    ) -> dict[str, Offence] | None:
        """BODY_NED (gate.md#receiver, #docs-vs-code): the receiver always ignores the position
        and takes a
        velocity or acceleration only with all three components; with nothing left it drops the
        message. Frames the docs do not list for the combination are OFB601's."""
        frame = event.coordinate_frame
        if event.kind != tm.LOCAL or frame != 8 or frame not in rules.frames_for(usable):
            return None
        if tm.body_ned_groups(event.type_mask):
            return None
        partial = sorted(g for g in ("velocity", "acceleration") if g in selected)
        why = "always ignores the position"
        if partial:
            why += (
                f" and takes {' or '.join(partial)} only with all three components used (an "
                "ignore bit on any one drops the whole vector)"
            )
        return {
            "body_ned": Offence(
                f"{head} selects {tm.describe_combo(selected)} in {tm.frame_name(frame)} "
                f"({frame}): the PX4 {self.ctx.profile.px4} docs list this frame for "
                f"{tm.describe_combo(usable)} setpoints on a {self.vehicle_label}, but in it "
                f"PX4's receiver {why}, so nothing is left and PX4 drops the message (no "
                "setpoint, no keep-alive)",
                short=f"type_mask {event.type_mask}: {tm.describe_combo(selected)} in "
                f"{tm.frame_name(frame)} leaves nothing: dropped, no keep-alive",
            )
        }

    def _mc_axes(self, event: PositionTarget, rx: ReceiverContext) -> dict[str, Offence]:
        """What PX4's multicopter position controller rejects (gate.md#multicopter, ``_inputValid``)
        in the setpoint the receiver makes of the message: each axis needs a finite position,
        velocity or acceleration, and x and y of each must be both finite or both NaN. Dropped
        messages are the other verdicts' (or OFB607's)."""
        mask, axes, _, _ = receive(event, rx)
        if mask == DROPPED or not axes:
            return {}
        finite = tuple(
            (bool(axes & 1 << shift), bool(axes & 2 << shift), bool(axes & 4 << shift))
            for shift in (0, 3, 6)
        )
        problems = _axis_problems(finite)
        if not problems:
            return {}
        fallback = (
            "reuses the last valid setpoint for up to 200 ms, then flies a failsafe hold"
            if self.ctx.profile.release.reuses_last_valid_setpoint
            else "flies a failsafe hold"
        )
        return {
            f"axes:{problems[0]}": Offence(
                f"{tm.MESSAGE_NAMES[event.kind]} type_mask {event.type_mask}: in the setpoint "
                f"PX4's receiver makes of it, {'; '.join(problems)} (a used field that is NaN "
                "counts as missing); PX4's multicopter position controller rejects such a "
                f"setpoint and {fallback} (no mode change, no failsafe flag); the docs' "
                "combinations use all three components of a group",
                short=clip(f"type_mask {event.type_mask}: {problems[0]}: PX4 holds instead"),
            )
        }

    # -- OFB603 -------------------------------------------------------------------------

    def _setpoint_type(self, event: PositionTarget, name: str) -> dict[str, Offence]:
        if self.group != "fixedwing" or "position" not in tm.selected_groups(event.type_mask):
            return {}
        kind = tm.setpoint_type(event.type_mask, event.kind)
        if kind is not None:
            return self._type_not_read(event, kind)
        values = tm.FIXEDWING_TYPES_LOCAL if event.kind == tm.LOCAL else tm.FIXEDWING_TYPES_GLOBAL
        listed = ", ".join(f"{v} {n}" for v, n in values.items())
        message = (
            f"fixed-wing {name} position setpoint with type_mask {event.type_mask} carries no "
            f"setpoint-type value ({listed}): the docs say the vehicle then flies a "
            "flower-like pattern"
        )
        short = f"fixed-wing position with type_mask {event.type_mask}: no setpoint type"
        if not self.ctx.profile.release.legacy_receiver:
            message += (
                f"; PX4 {self.ctx.profile.px4}'s receiver does not read these bits at all "
                "(v1.12+), so the value changes nothing there"
            )
            return {"type": Offence(message, Severity.INFO, short + " (PX4 ignores it)")}
        return {"type": Offence(message, short=short)}

    def _type_not_read(self, event: PositionTarget, kind: str) -> dict[str, Offence]:
        """A takeoff, land or idle type asks for an action; from v1.12 PX4's receiver reads no
        type bit and its fixed-wing controllers fly the setpoint as a position (with zero
        velocity, as the type clears every ignore bit: path following). Seen (SITL,
        ``fw_takeoff_type-*``): 4096 on the ground gave no runway takeoff on 1.16.2, 1.17.0
        or the 1.18 head."""
        if kind not in ACTION_TYPES or self.ctx.profile.release.legacy_receiver:
            return {}
        value = event.type_mask & tmask.SETPOINT_TYPE_BITS
        how = (
            " (with its velocity: path following)"
            if "velocity" in tm.selected_groups(event.type_mask)
            else ""
        )
        return {
            f"action:{value}": Offence(
                f"fixed-wing {tm.MESSAGE_NAMES[event.kind]} with the {kind} setpoint type "
                f"({value}): PX4 {self.ctx.profile.px4}'s receiver does not read the type bits "
                f"(v1.12+), so there is no {ACTION_TYPES[kind]}: the fixed-wing controller flies "
                f"the setpoint as a position{how}",
                short=f"fixed-wing {kind} type ({value}): PX4 does not read it, flies a position",
            )
        }

    # -- OFB604 -------------------------------------------------------------------------

    def _fw_ignored(
        self, event: PositionTarget, name: str, rules: tm.PositionTargetRules
    ) -> dict[str, Offence]:
        fields = [
            c
            for group in ("velocity", "acceleration")
            if group in rules.ignored
            for c in set_components(event, group)
        ]
        if not fields:
            return {}
        who = "fixed-wing" if self.group == "fixedwing" else "VTOL in FW flight,"
        message = (
            f"{who} {name} sets {', '.join(fields)}: the docs say fixed-wing uses the "
            "position only and ignores velocity and acceleration"
        )
        short = f"{who} {', '.join(fields)} set: fixed-wing takes the position only"
        if "position" in tm.selected_groups(event.type_mask):
            return {"ignored": Offence(message, Severity.WARNING, short)}
        # no position to fly: seen on 1.17.0 and the 1.18 head (vtol_fw_velocity-*), the
        # VTOL in FW flight neither turned to a velocity-only setpoint nor held its height
        return {
            "ignored": Offence(
                message + "; with no position in it PX4 does not fly it (seen: no turn to the "
                "velocity, the heading held, height lost)",
                Severity.ERROR,
                short + ": no position, PX4 does not fly it",
            )
        }

    # -- OFB605 -------------------------------------------------------------------------

    def _global_accel(self, event: PositionTarget) -> dict[str, Offence]:
        if event.kind != tm.GLOBAL or self.group != "copter":
            return {}
        if "acceleration" not in tm.selected_groups(event.type_mask):
            return {}
        return {
            "accel": Offence(
                f"SET_POSITION_TARGET_GLOBAL_INT type_mask {event.type_mask} uses afx/afy/afz: "
                "the docs say PX4 maps them to a normalised thrust, not an acceleration"
            )
        }

    def finish(self, t_end: float) -> None:
        self.episodes.finish()


# -- OFB609: the legacy receiver (PX4 legacy and 1.11) --------------------------------------

LEGACY_SETPOINT_TYPES = {0x1000: "takeoff", 0x2000: "land"}
"""Setpoint-type values the legacy receiver classifies as LOITER (v1.6.4-v1.11: it tests
``mask & 0x3000`` first; v1.5-v1.6.3 tested takeoff first, not modelled apart:
gate.md#receiver, #docs-vs-code)."""


def _nonfinite(names: tuple[str, ...], values: tuple[float, ...]) -> list[str]:
    return [n for n, v in zip(names, values, strict=True) if not math.isfinite(v)]


class LegacySetpointDropped(Check):
    """OFB609: what the legacy / 1.11 MAVLink receiver drops or does not forward
    (gate.md#receiver). Addressing is OFB607's."""

    codes = ("OFB609",)
    wants = (SetPositionTargetLocal, SetPositionTargetGlobal, SetAttitudeTarget)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.px4 = ctx.profile.px4
        self.global_int_handled = ctx.profile.release.handles_global_int
        self.stream_types = self.wants

    def on_event(self, event: Event) -> None:
        if event.origin != "sent":
            return
        offences = self._offences(event)
        if offences is not None:
            self.episodes.update("OFB609", event.kind, event.t, event.where, offences)

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: with every float field finite (``all_finite``) the offences depend only on
        the message type and its type_mask; then as ``commit_alike``, else replay."""
        events = sent_only(batch.of(self.stream_types))
        if not events:
            return
        if not all_finite(events):
            self.replay(batch)
            return
        first = first_of_each(_MASK_KEY, events)
        verdicts = [[("OFB609", self._offences(event) or {})] for event in first.values()]
        if not commit_alike(self.episodes, events[0].kind, events, verdicts):
            self.replay(batch)

    def _offences(self, event: Event) -> dict[str, Offence] | None:
        if isinstance(event, SetPositionTargetLocal):
            return self._local(event)
        if isinstance(event, SetPositionTargetGlobal):
            return self._global(event)
        if isinstance(event, SetAttitudeTarget):
            return self._attitude(event)
        return None

    def _dropped(self, name: str, fields: list[str], checked: str) -> dict[str, Offence]:
        return {
            "nonfinite": Offence(
                f"{name} carries a non-finite {', '.join(fields)}: PX4 {self.px4}'s receiver "
                f"drops the whole message unless {checked} are all finite, ignored or not (no "
                "setpoint, no keep-alive)"
            )
        }

    def _local(self, event: SetPositionTargetLocal) -> dict[str, Offence]:
        name = tm.MESSAGE_NAMES[tm.LOCAL]
        bad = _nonfinite(
            ("x", "y", "z", "vx", "vy", "vz", "afx", "afy", "afz", "yaw"),
            (*event.position, *event.velocity, *event.acceleration, event.yaw),
        )
        if bad:
            return self._dropped(name, bad, "x/y/z, vx/vy/vz, afx/afy/afz and yaw")
        mask = event.type_mask
        head = f"{name} type_mask {mask}"
        if mask & tmask.FORCE_SET and mask & tmask.POSITION_BITS and mask & tmask.VELOCITY_BITS:
            return {
                "force": Offence(
                    f"{head} sets the FORCE bit with position and velocity ignored: PX4 "
                    f'{self.px4}\'s receiver logs "force setpoint not supported" and forwards '
                    "no setpoint (the keep-alive still counts, so the vehicle stays in "
                    "offboard without a setpoint)"
                )
            }
        kind = LEGACY_SETPOINT_TYPES.get(mask & tmask.SETPOINT_TYPE_BITS)
        if kind is not None:
            value = mask & tmask.SETPOINT_TYPE_BITS
            return {
                f"type:{value}": Offence(
                    f"{head} carries the setpoint type {kind} ({value}): PX4 {self.px4}'s "
                    "receiver (v1.6.4-v1.11) tests the loiter value (mask & 0x3000) first, so "
                    f"it forwards a LOITER setpoint instead of a {kind} (only 12288 loiter and "
                    "16384 idle work as documented; v1.5-v1.6.3 tested takeoff first: there "
                    "4096 and 8192 worked and 12288 loiter became a TAKEOFF)"
                )
            }
        return {}

    def _global(self, event: SetPositionTargetGlobal) -> dict[str, Offence]:
        name = tm.MESSAGE_NAMES[tm.GLOBAL]
        if not self.global_int_handled:
            return {
                "global": Offence(
                    f"{name} is not handled by PX4's receiver before v1.10 (v1.5-v1.8 have no "
                    "handler): PX4 ignores it (no setpoint, no keep-alive); use "
                    "SET_POSITION_TARGET_LOCAL_NED"
                )
            }
        return {
            "global": Offence(
                f"{name} on PX4 1.11 goes to a legacy-style handler whose details are "
                "unverified: fuzzoff's gate model takes it as a keep-alive "
                "without a position setpoint; SET_POSITION_TARGET_LOCAL_NED is the safe choice",
                Severity.WARNING,
            )
        }

    def _attitude(self, event: SetAttitudeTarget) -> dict[str, Offence]:
        bad = _nonfinite(
            (
                "q[0]",
                "q[1]",
                "q[2]",
                "q[3]",
                "thrust",
                "body_roll_rate",
                "body_pitch_rate",
                "body_yaw_rate",
            ),
            (
                *event.q,
                event.thrust,
                event.body_roll_rate,
                event.body_pitch_rate,
                event.body_yaw_rate,
            ),
        )
        if bad:
            return self._dropped(
                tm.MESSAGE_NAMES[tm.ATTITUDE], bad, "q, thrust and the three body rates"
            )
        return {}

    def finish(self, t_end: float) -> None:
        self.episodes.finish()
