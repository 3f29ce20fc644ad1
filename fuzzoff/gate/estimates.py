"""What the gate knows about the vehicle's estimates and manual control (gate.md#signal, #loss).

Taken from ``FailsafeFlags`` events where the recording has them; a field the recording does not
carry (``None``) keeps its last value, and every field starts valid (gate.md#signal).
Manual control (RC or joystick) starts from the ``FUZZOFF_RC_PRESENT`` assumption.
"""

from __future__ import annotations

from dataclasses import field
from operator import attrgetter

from fuzzoff.events import ESTIMATES, FailsafeFlags
from fuzzoff.lean_dataclass import dataclass

_READ = attrgetter(*(name + "_valid" for name in ESTIMATES), "manual_control_signal_lost")
"""Every field of a ``FailsafeFlags`` event that ``Estimates.update`` applies."""


@dataclass(slots=True)
class Estimates:
    local_position: bool = True
    local_velocity: bool = True
    local_altitude: bool = True
    global_position: bool = True
    attitude: bool = True
    angular_velocity: bool = True
    home_position: bool = True
    rc_present: bool = True
    rc_recorded: bool = False
    """True once the recording said whether manual control is present."""
    recorded: bool = False
    """True once the recording carried any estimate flag."""
    bits: int = 255
    """Every flag the gate reads as one small integer (cheap change detection and memo keys)."""
    last_read: tuple[bool | None, ...] | None = field(default=None, compare=False, repr=False)
    """The fields of the last ``FailsafeFlags`` applied, as ``_READ`` reads them."""

    def __post_init__(self) -> None:
        self.bits = self._compute_key()

    def update(self, flags: FailsafeFlags) -> bool:
        """Apply a ``FailsafeFlags`` event; True when anything the gate reads changed."""
        read = _READ(flags)
        if read == self.last_read:  # PX4 logs the same flags at 10 Hz: nothing to apply
            return False
        self.last_read = read
        before = self.bits
        for name in ESTIMATES:
            value = getattr(flags, name + "_valid")
            if value is not None:
                setattr(self, name, bool(value))
                self.recorded = True
        if flags.manual_control_signal_lost is not None:
            self.rc_present = not flags.manual_control_signal_lost
            self.rc_recorded = True
        self.bits = self._compute_key()
        return self.bits != before

    def _compute_key(self) -> int:
        bits = (
            self.local_position,
            self.local_velocity,
            self.local_altitude,
            self.global_position,
            self.attitude,
            self.angular_velocity,
            self.home_position,
            self.rc_present,
        )
        return sum(1 << i for i, b in enumerate(bits) if b)
