"""Recorded mode history and acks vs the model's prediction (OFB202, ``fuzzoff gate``).

A recorded ``VehicleStatus`` agrees with the model when its nav_state equals the model's, or
equals the model's previous nav_state and the model changed less than the slack ago (the
recording lags), or the model reaches it within the slack (the recording leads: a loss whose
time the recording does not show is dated at the end of its window, PX4's 10 Hz check pass of
unknown phase, gate.md#check-timing, and the slack covers the window). Otherwise the difference
waits
``slack``; if it is still there it is confirmed once per episode (until the two agree again).

A mode that reached the recording over a link (HEARTBEAT, ``/mavros/state``) may also lag by
``LINK_LAG``.

Acks: PX4 1.16/1.17 ack a mode switch twice (4.3), so an ack is judged ``ACK_WINDOW`` after the
first one, by the last one. A request decided while the arming state was unknown carries the
outcome if armed as ``alternative``: its ack is handed back whatever it says, to settle which.
"""

from __future__ import annotations

from fuzzoff.events import Command, CommandAck, VehicleStatus
from fuzzoff.gate.requests import Decision
from fuzzoff.lean_dataclass import dataclass

INF = float("inf")
ACK_WINDOW = 0.1
"""Seconds within which a second ack for the same command replaces the first (4.3)."""
DECISION_MAX_AGE = 1.0
"""An ack later than this after the command is not matched to the model's decision."""
COMMAND_WINDOW = 1.5
"""A recorded change this close to a recorded command is the command's doing, not an unseen
input such as an RC switch."""
LINK_LAG = 0.5
"""How much later than the vehicle a mode reported over a link may be recorded (HEARTBEAT in a
ground-station tlog, ``/mavros/state``): transport latency, not PX4's timing."""
NOT_OFFBOARD = "no OFFBOARD on either side: other modes' own rules are not modelled; followed"
"""Said of a difference that does not concern the offboard gate (a ``mode`` row, not OFB202)."""
SAMPLED_SLACK = 0.1
"""Extra slack when the keep-alive is a logged, subsampled copy (ULog logs
``offboard_control_mode`` at 10 Hz, gate.md#seen-on-px4)."""


@dataclass(slots=True)
class Pending:
    t: float
    status: VehicleStatus
    latest: VehicleStatus


@dataclass(slots=True)
class Decided:
    t: float
    decision: Decision
    cmd: Command
    before: tuple[int | None, bool | None]
    target: int | None
    alternative: Decision | None = None
    """The decision were the vehicle armed, where the arming state was unknown and the two
    differ (``decision`` is then the one if disarmed)."""


@dataclass(slots=True)
class AckWait:
    t: float
    ack: CommandAck


def over_a_link(status: VehicleStatus) -> bool:
    """A mode sampled over a link (1 Hz HEARTBEAT, ``/mavros/state``), not published by PX4 on
    each change."""
    topic = status.where.topic
    return topic == "HEARTBEAT" or topic.endswith("/state")


class Comparator:
    def __init__(self, slack: float) -> None:
        self.base_slack = slack
        self.slack = slack
        self.pending: Pending | None = None
        self.open_episode = False
        self.changed_at = -INF
        self.nav_before: int | None = None
        self.decisions: dict[int, Decided] = {}
        self.ack_wait: AckWait | None = None
        self.last_command_t = -INF
        self.last_status: VehicleStatus | None = None
        self.last_ack_t: dict[int, float] = {}
        """The time of each command id's latest recorded ack."""
        self.unjudged: Command | None = None
        """The latest recorded command the model does not judge (NAV_LAND, RTL, ...): a mode
        the recording shows right after it is its doing, adopted from the recording."""

    def unjudged_before(self, t: float) -> Command | None:
        """The unjudged command a recorded change at ``t`` follows, if recent."""
        cmd = self.unjudged
        return cmd if cmd is not None and 0.0 <= t - cmd.t <= COMMAND_WINDOW else None

    def sampled_keepalive(self) -> None:
        self.slack = self.base_slack + SAMPLED_SLACK

    def difference_due(self) -> float:
        """When the pending difference is confirmed if it lasts (inf if none)."""
        return INF if self.pending is None else self.pending.t + self.slack

    def ack_due(self) -> float:
        """When the ack waiting for a second one is judged (inf if none). An ack due at the
        same time as a difference is judged first (``GateModel`` orders them so)."""
        return INF if self.ack_wait is None else self.ack_wait.t + ACK_WINDOW

    # -- modes

    def nav_changed(self, t: float, old: int | None, new: int | None) -> None:
        self.changed_at = t
        self.nav_before = old
        pending = self.pending
        if pending is not None and new == pending.latest.nav_state:
            self.pending = None

    def remember(self, status: VehicleStatus) -> None:
        self.last_status = status

    def recent_command(self, t: float) -> bool:
        return t - self.last_command_t <= COMMAND_WINDOW

    def observe(self, status: VehicleStatus, model_nav: int | None) -> None:
        recorded = status.nav_state
        if recorded is None or model_nav is None:
            return
        if recorded == model_nav:
            self.pending = None
            self.open_episode = False
            return
        lag = self.slack + (LINK_LAG if over_a_link(status) else 0.0)
        if status.t - self.changed_at <= lag and recorded == self.nav_before:
            return
        if self.open_episode:
            return
        if self.pending is None:
            self.pending = Pending(status.t, status, status)
        else:
            self.pending.latest = status

    def take_pending(self) -> Pending | None:
        pending = self.pending
        self.pending = None
        if pending is not None:
            self.open_episode = True
        return pending

    def drop_pending(self) -> None:
        """At the end of the recording a difference younger than the slack is not judged."""
        self.pending = None

    # -- acks

    def decided(
        self,
        cmd: Command,
        decision: Decision,
        before: tuple[int | None, bool | None],
        target: int | None,
        alternative: Decision | None = None,
    ) -> None:
        self.decisions[cmd.command] = Decided(cmd.t, decision, cmd, before, target, alternative)
        self.last_command_t = cmd.t

    def answered_between(self, command: int, start: float, end: float) -> bool:
        """Was an ack of ``command`` recorded at or after ``start`` and before ``end``?"""
        return start <= self.last_ack_t.get(command, -INF) < end

    def ack(self, ack: CommandAck) -> None:
        self.last_ack_t[ack.command] = ack.t
        decided = self.decisions.get(ack.command)
        if decided is None or ack.t - decided.t > DECISION_MAX_AGE:
            return
        wait = self.ack_wait
        if wait is not None and wait.ack.command == ack.command and ack.t - wait.t <= ACK_WINDOW:
            wait.ack = ack
            return
        self.ack_wait = AckWait(ack.t, ack)

    def take_ack(self) -> tuple[Decided, CommandAck] | None:
        """The judged ack if it disagrees with the model's decision or settles an undecided
        one, else None."""
        wait = self.ack_wait
        self.ack_wait = None
        if wait is None:
            return None
        decided = self.decisions.pop(wait.ack.command, None)
        if decided is None:
            return None
        if decided.alternative is None and wait.ack.accepted == decided.decision.accepted:
            return None
        return decided, wait.ack
