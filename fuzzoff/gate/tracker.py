"""Which controller runs in offboard, tracked over time (gate.md#control-mode to #rover).

``ControllerTracker`` keeps what the controllers see (the OCM flags, the newest trajectory
setpoint's per-axis content, the last valid setpoint for the 1.16+ 200 ms reuse) and reports a
``Change`` only when what runs changes, so the hot path (one setpoint per message) builds no
text. The tables themselves are in ``controllers``.
"""

from __future__ import annotations

from typing import Any

from fuzzoff.gate import controllers, ocm
from fuzzoff.gate.estimates import Estimates
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import nav_state_name
from fuzzoff.releases import Release

OFFBOARD = 14
INF = float("inf")


@dataclass(frozen=True, slots=True)
class Change:
    """A new answer to "which controller runs now"."""

    text: str
    spec: str
    reason: str | None = None
    unverified: bool = False


class ControllerTracker:
    def __init__(self, release: Release, vehicle_type: str, est: Estimates) -> None:
        self.release = release
        self.vehicle_type = vehicle_type
        self.est = est
        self.mask = 0
        self.position_control = False
        """The OCM switches the multicopter position controller on (mc, vtol)."""
        self.key: tuple[Any, ...] | None = None
        self.offboard_since = -INF
        self.traj_t = -INF
        self.traj_axes = -1
        self.last_valid_t = -INF
        self.reuse_due = INF
        """1.16+: when a reused last valid setpoint expires (section 8)."""
        self.kind = "none"
        self.legacy = not release.control_mode_flags
        """legacy/1.11: the offboard setpoint reaches mc_pos_control as
        ``position_setpoint_triplet`` (section 8 legacy note: details not modelled)."""
        self.reuses_last_valid = release.reuses_last_valid_setpoint
        self.setpoint_t = -INF
        """legacy/1.11: the newest offboard setpoint (triplet, MAVLink or trajectory setpoint)."""
        self._memo: dict[int, str | None] = {}
        self.land_speed = 0.7

    def set_mask(self, mask: int) -> None:
        self.mask = mask
        self.position_control = self.vehicle_type in ("mc", "vtol") and (
            controllers.position_control(self.release, mask)
        )

    def entered_offboard(self, t: float) -> None:
        self.offboard_since = t

    def setpoint(self, t: float) -> bool:
        """legacy/1.11: an offboard setpoint (a valid ``position_setpoint_triplet`` or a MAVLink
        setpoint); True when what runs may have changed (the first one)."""
        first = self.setpoint_t == -INF
        self.setpoint_t = t
        return first

    def trajectory(self, t: float, axes: int, in_offboard: bool) -> bool:
        """A trajectory setpoint; True when what runs may have changed (call ``update``)."""
        self.traj_t = t
        if self.legacy:
            self.traj_axes = axes
            return self.setpoint(t)
        if not in_offboard or not self.position_control:
            if axes != self.traj_axes:
                self.traj_axes = axes
                return self.vehicle_type == "fw" and in_offboard
            return False
        try:  # self.invalid(axes), inlined: once per setpoint
            invalid = self._memo[(axes << 8) | self.est.bits]
        except KeyError:
            invalid = self.invalid(axes)
        if invalid is None:
            self.last_valid_t = t
        if axes != self.traj_axes or invalid is not None or self.kind != "ok":
            self.traj_axes = axes
            return True
        return False

    def invalid(self, axes: int) -> str | None:
        """Why the position controller rejects this content (memoised per axes/estimates)."""
        key = (axes << 8) | self.est.bits
        try:
            return self._memo[key]
        except KeyError:
            value = self._memo[key] = controllers.mc_axes(axes, self.est)
            return value

    def update(self, t: float, nav: int | None) -> Change | None:
        """What runs at ``t`` with effective nav_state ``nav``, if it changed."""
        if nav != OFFBOARD:
            key: tuple[Any, ...] = (nav,)
            first = self.key is None
            changed = key != self.key
            self.key = key
            if changed and not first:
                return Change(f"offboard controllers off ({nav_state_name(nav)})", "7")
            return None
        if not self.position_control:
            fw = self._fw_state()
            key = (OFFBOARD, self.mask, fw)
            if key == self.key:
                return None
            self.key = key
            text, spec, unverified = controllers.describe(
                self.release, self.vehicle_type, self.mask
            )
            return Change(f"{text}; {fw}" if fw else text, spec, None, unverified)
        return self._multicopter(t)

    def _multicopter(self, t: float) -> Change | None:
        if self.legacy:
            return self._legacy_multicopter()
        mask, axes = self.mask, self.traj_axes
        invalid: str | None = None
        if self.traj_t < self.offboard_since:
            kind = "none"
            key: tuple[Any, ...] = (mask, kind, self.est.local_velocity)
        else:
            invalid = self.invalid(axes)
            if invalid is None:
                kind = "ok"
                key = (mask, kind, axes)
            elif self.reuses_last_valid and t < self.last_valid_t + controllers.LAST_VALID_S:
                kind = "reuse"
                self.reuse_due = self.last_valid_t + controllers.LAST_VALID_S
                key = (mask, kind, self.last_valid_t)
            else:
                kind = "failsafe"
                key = (mask, kind, self.est.local_velocity)
        self.kind = kind
        if key == self.key:
            return None
        self.key = key
        flags = ", ".join(controllers.control_flags(self.release, mask))
        head = f"multicopter offboard {ocm.names(ocm.first_flag(mask))} ({flags})"
        unverified = self.vehicle_type == "vtol" or self.release.old_code_unverified
        if kind == "ok":
            return Change(f"{head}: {controllers.mc_axes_text(axes)}", "8", None, unverified)
        if kind == "reuse":
            text = f"{head}: invalid setpoint ({invalid}): last valid setpoint reused for 200 ms"
            return Change(text, "8", invalid, unverified)
        hold = controllers.failsafe_setpoint(self.est, self.land_speed)
        if kind == "none":
            why = "no TrajectorySetpoint since position control was enabled"
            return Change(f"{head}: {hold} ({why})", "8", why, unverified)
        return Change(f"{head}: {hold} ({invalid})", "8", invalid, unverified)

    def _legacy_multicopter(self) -> Change | None:
        """legacy/1.11: mc_pos_control flies ``position_setpoint_triplet`` with its ``*_valid``
        flags (section 8 legacy note): not modelled per axis, so no hold is claimed."""
        seen = self.setpoint_t > -INF
        key = (self.mask, "legacy", seen)
        self.kind = "legacy"
        if key == self.key:
            return None
        self.key = key
        flags = ", ".join(controllers.control_flags(self.release, self.mask))
        head = f"multicopter offboard {ocm.names(ocm.first_flag(self.mask))} ({flags})"
        if seen:
            text = f"{head}: setpoint from position_setpoint_triplet (not modelled per axis)"
            return Change(text, "8", None, True)
        why = "no offboard setpoint recorded yet"
        text = f"{head}: {why} (what legacy mc_pos_control flies then: not modelled)"
        return Change(text, "8", why, True)

    def _fw_state(self) -> str:
        if self.vehicle_type != "fw" or ocm.first_flag(self.mask) != ocm.POSITION:
            return ""
        axes = self.traj_axes
        if axes < 0:
            return "no trajectory setpoint yet"
        if axes & 0b111000 == 0b111000:
            return "path following (velocity finite)"
        if axes & 0b111 == 0b111:
            return "position (FW_POSCTRL_MODE_AUTO)"
        return "setpoint invalid: needs all three position or velocity components"
