"""An executable model of PX4's offboard gate, following PX4's code per version and vehicle.

``GateModel(profile, params).feed(event)`` returns the transitions the event causes (after the
model has advanced its clock to ``event.t``, which may itself time out the signal);
``finish(t_end)`` flushes timeouts up to the end of the recording. See docs/gate.md (its
sections and "Code layout"). ``model`` is the façade; its parts, sharing one ``state.GateState``:
``keepalive`` (keep-alives and the loss window, 2), ``verdict`` (PX4's recorded verdict on the
signal), ``mavlink`` (the MAVLink receiver, 6) and ``setpoints`` (controllers, 7-10),
``effective`` (the effective mode and loss action, 5), ``commander`` (requests, 4 and 13a),
``history`` and ``acks`` (the recording against the prediction, 12 and 4.3). The tables and
small models they use: ``signal``, ``requests``, ``failsafe``, ``receiver``, ``controllers``,
``tracker``, ``landed``, ``params`` (13), ``compare``. Checks read the model through
``view.GateView``.
"""

from fuzzoff.gate.model import GateModel
from fuzzoff.gate.transitions import GateTransition, TransitionKind
from fuzzoff.gate.view import GateView

__all__ = ["GateModel", "GateTransition", "GateView", "TransitionKind"]
