"""A ROS 2 node flying PX4's standard VTOL offboard over the bridge (issue 33).

As the px4_ros_com example (``example.py``) on the same three topics: every 100 ms an
``OffboardControlMode`` (position only) and a ``TrajectorySetpoint`` (a position; velocity,
acceleration, jerk, yaw and yaw rate NaN: PX4's controllers fill them); on its 11th tick
DO_SET_MODE (OFFBOARD) and ARM as the example. The position is ``VtolPlan.mc_point`` (climb
and hover in MC) until ``transition_after_arm_s``, when the node sends
``VEHICLE_CMD_DO_VTOL_TRANSITION`` to FW while in OFFBOARD and streams ``fw_point`` from then
on (the MAVLink scenarios' ``vtol_offboard`` and ``vtol_loss``, ``fuzzoff.sitl.scenarios``).
``VtolPlan.stops``: windows (after the arm) in which the node publishes nothing, then resumes.

The airplane's ground gate (the MAVLink ``fw_gate``) is the same node without a transition:
the point where it stands, a stop, and ``disarm_after_arm_s`` a DISARM, then a forced one
(param2 21196) half a second later if PX4's status still says armed (PX4 refuses a plain
disarm while it counts the rolling airplane as flying).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl.ros2.example import (
    PX4_CUSTOM_MAIN_MODE_OFFBOARD,
    SETPOINTS_BEFORE_SWITCH,
    VEHICLE_CMD_COMPONENT_ARM_DISARM,
    VEHICLE_CMD_DO_SET_MODE,
    Sink,
    now_us,
    send_vehicle_command,
)

VEHICLE_CMD_DO_VTOL_TRANSITION = 3000
FORCE_DISARM = 21196.0
"""param2 of ARM_DISARM that disarms in flight."""
FORCE_AFTER_S = 0.5
VTOL_STATE_FW = 4.0
"""``vtol_vehicle_status`` FW state: param1 of DO_VTOL_TRANSITION (MAV_VTOL_STATE_FW)."""
NAN = math.nan
MC_POINT = (0.0, 0.0, -20.0)
"""Climb and hover in MC 20 m up (NED), as ``scenarios.VTOL_MC_ALT``."""
FW_POINT = (400.0, 0.0, -30.0)
"""Fly here in FW (``scenarios.VTOL_FW_POINT``): still on its way when the flight ends."""


@dataclass(frozen=True, slots=True)
class VtolPlan:
    transition_after_arm_s: float | None = 11.0
    """None: no transition (the airplane on the ground)."""
    mc_point: tuple[float, float, float] = MC_POINT
    fw_point: tuple[float, float, float] = FW_POINT
    stops: tuple[tuple[float, float], ...] = ()
    """(after the arm, for how long) the node publishes nothing, then resumes."""
    setpoints_before_switch: int = SETPOINTS_BEFORE_SWITCH
    disarm_after_arm_s: float | None = None
    """The node disarms this long after the arm (forced if PX4 still shows it armed)."""


class VtolNode:
    """One VTOL node: ``tick()`` is its 100 ms timer callback (``example.OffboardControl``'s
    interface: ``armed_at``, ``notes``)."""

    def __init__(
        self, sinks: Mapping[str, Sink], plan: VtolPlan, armed: Callable[[], bool] | None = None
    ) -> None:
        """``armed()``: whether PX4's status says armed (for the forced disarm)."""
        self.sinks = sinks
        self.plan = plan
        self.armed = armed or (lambda: False)
        self.disarmed_at: float | None = None
        self.forced = False
        self.counter = 0
        self.armed_at: float | None = None
        self.transitioned = False
        self.silent = False
        self.notes: list[tuple[float, str]] = []

    def _after_arm(self, now: float) -> float | None:
        return None if self.armed_at is None else now - self.armed_at

    def tick(self, now: float) -> None:
        since = self._after_arm(now)
        quiet = since is not None and any(a <= since < a + d for a, d in self.plan.stops)
        if quiet != self.silent:
            self.silent = quiet
            phase = "FW" if self.transitioned else "MC"
            where = f" ({phase})" if self.plan.transition_after_arm_s is not None else ""
            self.notes.append((now, f"stream {'stops' if quiet else 'resumes'}{where}"))
        if quiet:
            return
        if self.counter == self.plan.setpoints_before_switch:
            self._command(VEHICLE_CMD_DO_SET_MODE, 1.0, PX4_CUSTOM_MAIN_MODE_OFFBOARD)
            self._command(VEHICLE_CMD_COMPONENT_ARM_DISARM, 1.0)
            self.armed_at = now
            self.notes.append((now, "DO_SET_MODE offboard and ARM sent"))
        since = self._after_arm(now)
        transition = self.plan.transition_after_arm_s
        if (
            not self.transitioned
            and since is not None
            and transition is not None
            and since >= transition
        ):
            self.transitioned = True
            self._command(VEHICLE_CMD_DO_VTOL_TRANSITION, VTOL_STATE_FW)
            self.notes.append((now, "DO_VTOL_TRANSITION to FW sent"))
        self._disarm(now, since)
        point = self.plan.fw_point if self.transitioned else self.plan.mc_point
        self.sinks["OffboardControlMode"].publish(
            timestamp=now_us(),
            position=True,
            velocity=False,
            acceleration=False,
            attitude=False,
            body_rate=False,
        )
        self.sinks["TrajectorySetpoint"].publish(
            timestamp=now_us(),
            position=list(point),
            velocity=[NAN, NAN, NAN],
            acceleration=[NAN, NAN, NAN],
            jerk=[NAN, NAN, NAN],
            yaw=NAN,
            yawspeed=NAN,
        )
        if self.counter <= self.plan.setpoints_before_switch:
            self.counter += 1

    def _disarm(self, now: float, since: float | None) -> None:
        after = self.plan.disarm_after_arm_s
        if after is None or since is None or since < after:
            return
        if self.disarmed_at is None:
            self.disarmed_at = now
            self._command(VEHICLE_CMD_COMPONENT_ARM_DISARM, 0.0)
            self.notes.append((now, "DISARM sent"))
        elif not self.forced and now - self.disarmed_at >= FORCE_AFTER_S and self.armed():
            self.forced = True
            self._command(VEHICLE_CMD_COMPONENT_ARM_DISARM, 0.0, FORCE_DISARM)
            self.notes.append((now, "still armed: forced DISARM sent"))

    def _command(self, command: int, param1: float = 0.0, param2: float = 0.0) -> None:
        send_vehicle_command(self.sinks["VehicleCommand"], command, param1, param2)
