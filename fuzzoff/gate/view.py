"""What a check may read of the gate model: its prediction and what the prediction rests on.

``GateView`` is the read-only face the engine hands the checks (``CheckContext.gate``): the live
``GateModel``, or while a run of stream messages is judged (``StreamBatch``) a ``GateSnapshot``
of the model as those messages saw it.
"""

from __future__ import annotations

from typing import Protocol

from fuzzoff.events import NAV_STATE_OFFBOARD
from fuzzoff.gate.compare import Comparator
from fuzzoff.gate.estimates import Estimates
from fuzzoff.gate.failsafe import LossAction, loss_action
from fuzzoff.gate.receiver import ReceiverContext
from fuzzoff.gate.state import GateState
from fuzzoff.releases import Release


class GateView(Protocol):
    @property
    def nav_state(self) -> int | None:
        """The effective nav_state the model predicts."""

    @property
    def in_offboard(self) -> bool:
        """The model predicts OFFBOARD."""

    @property
    def offboard_since(self) -> float | None:
        """When the prediction last entered OFFBOARD (None while it is not OFFBOARD)."""

    @property
    def armed(self) -> bool | None:
        """The model's arming state (None: the recording has not shown it)."""

    @property
    def user_intention(self) -> int | None: ...

    @property
    def signal_ok(self) -> bool:
        """The offboard signal is available."""

    @property
    def loss_timeout(self) -> float: ...

    @property
    def follows_flag(self) -> bool:
        """Without the stream, the signal follows PX4's recorded verdict."""

    @property
    def params(self) -> dict[str, float]:
        """Effective parameters: PX4's defaults < the recording's < the user's overrides."""

    @property
    def overrides(self) -> dict[str, float]: ...

    @property
    def recorded_params(self) -> dict[str, float]: ...

    @property
    def est(self) -> Estimates: ...

    @property
    def receiver(self) -> ReceiverContext:
        """What PX4's MAVLink receiver reads besides the message (parameters, estimates)."""

    @property
    def compare(self) -> Comparator:
        """The comparison with the recorded history (its ``slack``)."""

    def current_loss_action(self) -> LossAction:
        """What the vehicle would do if the signal were lost now (OFB701/OFB702)."""

    def snapshot(self) -> GateView:
        """The view as it is now, for a run of messages that all see it so."""


class GateSnapshot:
    """The gate as the messages of a run saw it: the prediction is frozen; the parameters,
    estimates, receiver context and comparison are the live model's (only an event that
    closes a run changes them)."""

    __slots__ = (
        "_release",
        "_vehicle_type",
        "armed",
        "compare",
        "est",
        "follows_flag",
        "in_offboard",
        "loss_timeout",
        "nav_state",
        "offboard_since",
        "overrides",
        "params",
        "receiver",
        "recorded_params",
        "signal_ok",
        "user_intention",
    )

    def __init__(self, state: GateState) -> None:
        self.nav_state = state.nav
        self.in_offboard = state.nav == NAV_STATE_OFFBOARD
        self.offboard_since = state.offboard_since
        self.armed = state.armed
        self.user_intention = state.user_intention
        self.signal_ok = state.signal.available
        self.loss_timeout = state.signal.timeout
        self.follows_flag = state.follows_flag
        self.params = state.params
        self.overrides = state.overrides
        self.recorded_params = state.recorded_params
        self.est = state.est
        self.receiver = state.rx
        self.compare = state.compare
        self._release: Release = state.release
        self._vehicle_type = state.vehicle_type

    def current_loss_action(self) -> LossAction:
        return loss_action(self._release, self._vehicle_type, self.params, self.est)

    def snapshot(self) -> GateSnapshot:
        return self
