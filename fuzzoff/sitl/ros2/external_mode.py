"""An external mode's side of PX4's mode registration, as px4-ros2-interface-lib does it.

What the library does (its ``Registration`` and ``HealthAndArmingChecks`` components): it
publishes one ``RegisterExtComponentRequest`` (a random request id, the mode's name, its own
``px4_ros2_api_version``, an arming check and a mode); when PX4's
``RegisterExtComponentReply`` for that id says success with the library's API version, the mode
is registered and the node answers every ``ArmingCheckRequest`` with an ``ArmingCheckReply``
for its arming-check id (the mode's requirements, ``can_arm_and_run``). A reply with another API
version makes the library give up ("Incompatible ROS2 library API version"): it answers nothing,
although PX4 registered the mode. ``ModePlan.api_version`` chooses what the node asks with;
``unregister_after_s`` makes it unregister (``UnregisterExtComponent``) that long after it
registered, as the library does when its node shuts down; ``stops_after_s`` makes it die
without unregistering.
"""

from __future__ import annotations

import time
from typing import Any

from fuzzoff.lean_dataclass import dataclass
from fuzzoff.sitl.ros2.example import Sink, now_us

REQUEST_ID = 4711
"""The request's id (the library draws a random one; fixed here, for repeatable runs)."""
MODE_NAME = "fuzzoff mode"
SENT = ("RegisterExtComponentRequest", "ArmingCheckReply", "UnregisterExtComponent")
RECEIVED = ("RegisterExtComponentReply", "ArmingCheckRequest")


@dataclass(frozen=True, slots=True)
class ModePlan:
    api_offset: int = 0
    """The ``px4_ros2_api_version`` the node asks with (the library's own constant), relative
    to the release's (``Release.external_mode_api``): -1 is a library built for the API
    before it (px4-ros2-interface-lib 2.1.1, API 1, on PX4 1.18, API 2)."""
    unregister_after_s: float | None = None
    stops_after_s: float | None = None
    """The node dies this long after it registered (a watchdog or a crash, px4-ros2-interface-lib
    #195): it answers nothing more and does not unregister."""


def name_field(name: str) -> list[int]:
    raw = name.encode("utf-8")[:24]
    return [*raw, *([0] * (25 - len(raw)))]


class ExternalMode:
    """One mode's node: ``start`` registers, ``on_reply`` / ``on_check`` are its callbacks
    (called from the recorder's thread as PX4's messages arrive), ``tick`` its timer."""

    def __init__(self, sinks: dict[str, Sink], plan: ModePlan, release_api: int) -> None:
        self.request = sinks["RegisterExtComponentRequest"]
        self.answer = sinks["ArmingCheckReply"]
        self.unregister = sinks["UnregisterExtComponent"]
        self.plan = plan
        self.api_version = release_api + plan.api_offset
        self.reply: Any = None
        self.registered_at: float | None = None
        self.gave_up = False
        self.unregistered = False
        self.dead = False
        self.answered = 0
        self.notes: list[tuple[float, str]] = []

    def start(self, now: float) -> None:
        self.request.publish(
            timestamp=now_us(),
            request_id=REQUEST_ID,
            name=name_field(MODE_NAME),
            px4_ros2_api_version=self.api_version,
            register_arming_check=True,
            register_mode=True,
        )
        self.notes.append((now, f"registration sent (API version {self.api_version})"))

    def on_reply(self, reply: Any) -> None:
        if reply.request_id != REQUEST_ID or self.reply is not None:
            return
        now = time.monotonic()
        self.reply = reply
        if not reply.success:
            self.notes.append((now, "PX4 refused the registration"))
        elif reply.px4_ros2_api_version != self.api_version:
            self.gave_up = True
            self.notes.append(
                (
                    now,
                    f"PX4 answered API version {reply.px4_ros2_api_version}: the node gives up"
                    " (Incompatible ROS2 library API version)",
                )
            )
        else:
            self.registered_at = now
            self.notes.append(
                (now, f"registered: arming check {reply.arming_check_id}, mode {reply.mode_id}")
            )

    def on_check(self, request: Any) -> None:
        if self.registered_at is None or self.unregistered or self.dead:
            return
        self.answer.publish(
            timestamp=now_us(),
            request_id=request.request_id,
            registration_id=self.reply.arming_check_id,
            can_arm_and_run=True,
            mode_req_angular_velocity=True,
            mode_req_attitude=True,
            mode_req_local_alt=True,
            mode_req_local_position=True,
        )
        self.answered += 1

    def tick(self, now: float) -> None:
        dies = self.plan.stops_after_s
        since = None if self.registered_at is None else now - self.registered_at
        if dies is not None and since is not None and since >= dies and not self.dead:
            self.dead = True
            self.notes.append((now, "the node dies (no unregistration)"))
        after = self.plan.unregister_after_s
        if after is None or self.registered_at is None or self.unregistered:
            return
        if now - self.registered_at >= after:
            self.unregistered = True
            self.unregister.publish(
                timestamp=now_us(),
                name=name_field(MODE_NAME),
                arming_check_id=self.reply.arming_check_id,
                mode_id=self.reply.mode_id,
                mode_executor_id=-1,
            )
            self.notes.append((now, "unregistered"))
