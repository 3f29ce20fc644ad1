"""OFB209: an external mode PX4 refuses, or drops because its arming checks go unanswered.

An external mode (px4-ros2-interface-lib, PX4 1.15+) lives by three exchanges, all on the
ROS 2 bridge and all in a recording of it (``fuzzoff/formats/uorb.py``):

* registration: the companion's ``RegisterExtComponentRequest``; PX4's ``ModeManagement``
  answers with ``RegisterExtComponentReply``: ``success`` false when the vehicle is armed, when
  the request is malformed (a mode without an arming check, an executor without a mode) or when
  there is no free slot; the reply always carries PX4's own ``LATEST_PX4_ROS2_API_VERSION``
  (``Release.external_mode_api``), and the library refuses a reply whose version is not the
  one it was built for ("Incompatible ROS2 library API version"): it gives up, although PX4
  registered the mode;
* liveness: PX4 publishes an ``ArmingCheckRequest`` every 300 ms and counts, per registration,
  the requests in a row that got no ``ArmingCheckReply`` within 50 ms; more than 3 (more than 10
  before the registration's first reply) make it unresponsive: PX4 removes the mode when it is
  not the selected one and the vehicle is disarmed, and a selected mode can no longer run
  (``externalChecks.cpp``, ``ModeManagement.cpp``; PX4 1.17+ also clears the registration's bit
  in ``valid_registrations_mask``, its own verdict);
* ``UnregisterExtComponent``: PX4 removes the mode; while armed PX4 takes no unregistration, and
  the node that sent it answers no more arming checks.

A reply is not always recorded (PX4's reply on a topic the bag did not record, a request on a
topic PX4 does not read): a request whose API version is not the one the release expects is
then judged by the release (``--px4``).
"""

from __future__ import annotations

from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import (
    ArmingCheckReply,
    ArmingCheckRequest,
    Event,
    ExtComponentReply,
    ExtComponentRequest,
    ExtComponentUnregister,
)
from fuzzoff.lean_dataclass import dataclass

CODE = "OFB209"

REQUEST_PERIOD_S = 0.3
"""PX4 asks for arming checks every 300 ms (``ExternalChecks::UPDATE_INTERVAL``)."""
MISSES = 3
"""More than this many requests in a row without a reply: unresponsive."""
MISSES_FIRST = 10
"""The same before the registration's first reply (ROS 2 needs a while to match)."""
FIRST_EXTERNAL_NAV_STATE = 23
"""``NAVIGATION_STATE_EXTERNAL1``: an external mode's id is its nav_state."""


@dataclass(slots=True)
class _Registration:
    name: str
    mode_id: int
    since: float
    replied: bool = False
    misses: int = 0
    last_reply: float | None = None
    dropped: bool = False


class ExternalModes(Check):
    """OFB209: one finding per refused registration, per registration PX4 drops, per mode
    unregistered while the vehicle flies in it."""

    codes = (CODE,)
    wants = (
        ExtComponentRequest,
        ExtComponentReply,
        ArmingCheckRequest,
        ArmingCheckReply,
        ExtComponentUnregister,
    )

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.requests: dict[int, ExtComponentRequest] = {}
        self.answered: set[int] = set()
        self.registrations: dict[int, _Registration] = {}
        self.check_request: ArmingCheckRequest | None = None
        self.replied: set[int] = set()
        self.replies_seen = False

    def on_event(self, event: Event) -> None:
        if isinstance(event, ExtComponentRequest):
            self.requests[event.request_id] = event
        elif isinstance(event, ExtComponentReply):
            self._reply(event)
        elif isinstance(event, ArmingCheckRequest):
            self._next_request(event)
        elif isinstance(event, ArmingCheckReply):
            self.replies_seen = True
            if self.check_request is not None and event.request_id == self.check_request.request_id:
                self.replied.add(event.registration_id)
            held = self.registrations.get(event.registration_id)
            if held is not None:
                held.replied, held.misses, held.last_reply = True, 0, event.t
        elif isinstance(event, ExtComponentUnregister):
            self._unregister(event)

    # -- registration ------------------------------------------------------------------------

    def _reply(self, reply: ExtComponentReply) -> None:
        request = self.requests.get(reply.request_id)
        self.answered.add(reply.request_id)
        name = reply.name or (request.name if request is not None else "")
        what = f"the registration of {name!r}" if name else "a registration"
        if not reply.success:
            self.ctx.report(
                CODE,
                f"PX4 refused {what} (RegisterExtComponentReply success false, request "
                f"{reply.request_id}): {self._why_refused(request)}; the mode does not exist and "
                "a switch to it is rejected",
                reply.t,
                reply.where,
                short=f"PX4 refused {what}",
            )
            return
        if request is not None and request.api_version != reply.api_version:
            self.ctx.report(
                CODE,
                f"{what.capitalize()} asked with API version {request.api_version}, and PX4 "
                f"answered with its own, {reply.api_version}: px4-ros2-interface-lib built for "
                f'API {request.api_version} refuses the reply itself ("Incompatible ROS2 library '
                'API version") and stops, while PX4 registered the mode; its arming checks then '
                "go unanswered and PX4 removes it",
                reply.t,
                reply.where,
                short=(
                    f"API version {request.api_version} asked, PX4 speaks "
                    f"{reply.api_version}: the library gives up"
                ),
            )
            return
        if reply.arming_check_id >= 0:
            self.registrations[reply.arming_check_id] = _Registration(name, reply.mode_id, reply.t)

    def _why_refused(self, request: ExtComponentRequest | None) -> str:
        if self.ctx.state.armed:
            return "PX4 takes no registration while the vehicle is armed"
        if request is not None and request.mode and not request.arming_check:
            return "a mode must register its arming check with it"
        if request is not None and request.executor and not request.mode:
            return "a mode executor must register its mode with it"
        return (
            "no free slot for the arming check, the mode or the executor, or another external "
            "mode already replaces the internal mode this one would replace"
        )

    # -- liveness ----------------------------------------------------------------------------

    def _next_request(self, request: ArmingCheckRequest) -> None:
        if self.check_request is not None:
            self._close(self.check_request)
        mask = request.registrations_mask
        if mask is not None:
            for reg_id, held in self.registrations.items():
                known = held.replied or held.misses  # PX4 has counted it since registering
                if not held.dropped and known and not mask >> reg_id & 1:
                    self._dropped(reg_id, held, request, by_px4=True)
        self.check_request, self.replied = request, set()

    def _close(self, request: ArmingCheckRequest) -> None:
        """The replies to ``request`` are in: count a miss for each registration without one."""
        if not self._judged():
            return
        for reg_id, held in self.registrations.items():
            if held.dropped or reg_id in self.replied:
                continue
            held.misses += 1
            limit = MISSES if held.replied else MISSES_FIRST
            if held.misses > limit:
                self._dropped(reg_id, held, request, by_px4=False)

    def _judged(self) -> bool:
        """The companion's side is in the recording (its replies, or its own requests)."""
        return self.replies_seen or self.ctx.has("arming_check_reply", "ext_component_request")

    def _dropped(
        self, reg_id: int, held: _Registration, at: ArmingCheckRequest, *, by_px4: bool
    ) -> None:
        held.dropped = True
        name = f"{held.name!r}" if held.name else f"registration {reg_id}"
        since = held.last_reply if held.last_reply is not None else held.since
        how = (
            "PX4 no longer lists it among its valid registrations (valid_registrations_mask)"
            if by_px4
            else f"{held.misses} arming-check requests in a row got no reply (PX4 allows "
            f"{MISSES if held.replied else MISSES_FIRST})"
        )
        selected = self.ctx.state.status_nav_state == held.mode_id >= FIRST_EXTERNAL_NAV_STATE
        fate = (
            "the vehicle is in that mode, which can no longer run: PX4 leaves it"
            if selected and self.ctx.state.armed
            else "PX4 removes the mode (it disappears from the ground station and a switch to "
            "it is rejected)"
        )
        self.ctx.report(
            CODE,
            f"External mode {name} stopped answering PX4's arming checks "
            f"{at.t - since:.1f} s before this request: {how}; {fate}. The node that "
            "registered it stopped or stalled (a watchdog, a crash, a blocked executor)",
            at.t,
            at.where,
            short=f"external mode {name}: arming checks unanswered, PX4 drops it",
        )

    # -- unregistration ----------------------------------------------------------------------

    def _unregister(self, event: ExtComponentUnregister) -> None:
        held = self.registrations.pop(event.arming_check_id, None)
        mode_id = event.mode_id if event.mode_id >= 0 else (held.mode_id if held else -1)
        state = self.ctx.state
        if mode_id < FIRST_EXTERNAL_NAV_STATE or not state.armed:
            return
        if state.status_nav_state != mode_id:
            return
        name = event.name or (held.name if held is not None else f"mode {mode_id}")
        self.ctx.report(
            CODE,
            f"External mode {name!r} unregistered while the vehicle flies in it: PX4 takes no "
            "unregistration while armed, the node answers no more arming checks, and the mode "
            "PX4 is flying can no longer run: PX4 leaves it for a failsafe action",
            event.t,
            event.where,
            short=f"external mode {name!r} unregistered in flight",
        )

    def finish(self, t_end: float) -> None:
        last = self.check_request
        if last is not None and t_end - last.t >= REQUEST_PERIOD_S:
            # the last request's replies were due long before the end (PX4 stops asking
            # once it has dropped the last registration, so no next request closes it)
            self._close(last)
        expected = self.ctx.profile.release.external_mode_api
        for request_id, request in self.requests.items():
            if request_id in self.answered or expected is None:
                continue
            if request.api_version == expected:
                continue
            self.ctx.report(
                CODE,
                f"The registration of {request.name!r} asks for API version "
                f"{request.api_version}; PX4 {self.ctx.profile.release.name} speaks "
                f"{expected} (no reply in the recording): px4-ros2-interface-lib built for "
                f"API {request.api_version} refuses PX4's reply and the mode never works",
                request.t,
                request.where,
                short=f"API version {request.api_version} asked, PX4 speaks {expected}",
            )
