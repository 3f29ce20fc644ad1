"""An executable model of PX4's offboard gate, following PX4's code per version and vehicle.

``GateModel(profile, params).feed(event)`` returns the transitions the event causes (after the
model has advanced its clock to ``event.t``, which may itself time out the signal);
``finish(t_end)`` flushes timeouts up to the end of the recording. See px4-offboard-gate.md and
docs/gate.md. Modules: ``signal`` (proof of life, 2), ``requests`` (switch and arm, 4),
``failsafe`` (loss action, 5), ``receiver`` (MAVLink receiver, 6), ``controllers`` and
``tracker`` (7-10), ``params`` (13), ``compare`` (recording vs model), ``model``.
"""

from fuzzoff.gate.model import GateModel
from fuzzoff.gate.transitions import GateTransition, TransitionKind

__all__ = ["GateModel", "GateTransition", "TransitionKind"]
