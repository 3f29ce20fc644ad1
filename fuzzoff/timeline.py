"""The series of one vehicle's run that the gate command and the HTML report show, filled by
the engine (``engine.VehicleRun`` with a timeline) and read by the renderers: a plain record,
in a module of its own so that what reads it need not import the engine."""

from __future__ import annotations

from dataclasses import field

from fuzzoff.events import Event
from fuzzoff.gate.transitions import GateTransition
from fuzzoff.lean_dataclass import dataclass


@dataclass(slots=True)
class Timeline:
    """Optional per-vehicle series for the gate command and the HTML report."""

    keepalive: list[float] = field(default_factory=list)
    recorded_modes: list[tuple[float, int | None, bool | None]] = field(default_factory=list)
    transitions: list[GateTransition] = field(default_factory=list)
    setpoint_kinds: dict[str, list[float]] = field(default_factory=dict)
    loss_timeout: float | None = None
    """The gate's effective loss timeout (recording's COM_OF_LOSS_T, overrides, defaults)."""
    recorded_params: dict[str, float] = field(default_factory=dict)
    notes: list[Event] = field(default_factory=list)
    """The vehicle's text messages, the commands sent and their acks (at most
    ``engine.NOTE_LIMIT``)."""
    positions: list[tuple[float, float, float, float]] = field(default_factory=list)
    """(t, x, y, z) of the vehicle's local position, NED metres, one per
    ``recording.PLOT_SAMPLE_S`` at most: the positions judged, and those the reader thinned out
    of the events (``recording.PlotSamples``)."""
    setpoint_positions: list[tuple[float, float, float, float]] = field(default_factory=list)
    """(t, x, y, z) of the position setpoints (trajectory setpoints, local NED MAVLink ones)."""
