"""PX4 version profiles and vehicle types (docs/gate.md, docs/rules).

A profile is the pair (PX4 profile, vehicle type). ``--px4`` takes a release such as ``1.15.4``
and maps it to the modelled profile; the report always says whether it was detected. What each
PX4 profile does is its record in ``fuzzoff/releases.py`` (``Profile.release``).
"""

from __future__ import annotations

from fuzzoff import releases
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.releases import PX4Profile, Release

VEHICLE_TYPES: tuple[str, ...] = (
    "mc",
    "fw",
    "vtol",
    "rover-ackermann",
    "rover-differential",
    "rover-mecanum",
)

VEHICLE_NOTES: dict[str, str] = {
    "mc": "multicopter",
    "fw": "fixed-wing",
    "vtol": "VTOL",
    "rover-ackermann": "Ackermann rover",
    "rover-differential": "differential rover",
    "rover-mecanum": "mecanum rover",
}

DEFAULT_PX4: PX4Profile = "1.15"
DEFAULT_VEHICLE = "mc"


class ProfileError(ValueError):
    """An unknown PX4 version or vehicle type (a usage error)."""


def px4_profile_for(version: str) -> PX4Profile:
    """Map a release (``1.15.4``, ``v1.17.0-beta1``) or a profile name to the modelled profile."""
    found = releases.named(version)
    if found is None:
        raise ProfileError(
            f"unknown PX4 version {version!r}: give a release such as 1.15.4, "
            f"or one of {', '.join(releases.names())}"
        )
    return found.name  # type: ignore[return-value]


def px4_notes() -> dict[str, str]:
    """Profile name -> what it covers, oldest first (``fuzzoff profiles``)."""
    return {r.name: r.covers for r in releases.RELEASES}


def px4_seen_running() -> dict[str, tuple[str, ...]]:
    """Profile name -> the PX4 SITL builds it was checked against live (empty: from the code
    only), oldest first."""
    return {r.name: releases.SEEN_RUNNING.get(r.name, ()) for r in releases.RELEASES}


def seen_running_text(names: tuple[str, ...]) -> str:
    """Which of ``names`` were seen running on PX4 and which are modelled from the code only."""
    seen = px4_seen_running()
    live = [f"{n} ({', '.join(seen[n])})" for n in names if seen.get(n)]
    code = [n for n in names if not seen.get(n)]
    parts = []
    if live:
        parts.append("Seen running (PX4 SITL builds): " + "; ".join(live))
    if code:
        parts.append("Modelled from the code only: " + ", ".join(code))
    return ". ".join(parts)


def vehicle_type_for(name: str) -> str:
    """Validate and normalise a vehicle type name (``rover`` alone means differential)."""
    text = name.strip().lower()
    aliases = {
        "multicopter": "mc",
        "copter": "mc",
        "quad": "mc",
        "fixedwing": "fw",
        "fixed-wing": "fw",
        "plane": "fw",
        "rover": "rover-differential",
    }
    text = aliases.get(text, text)
    if text not in VEHICLE_TYPES:
        raise ProfileError(f"unknown vehicle type {name!r}: one of {', '.join(VEHICLE_TYPES)}")
    return text


def is_rover(vehicle: str) -> bool:
    return vehicle.startswith("rover")


@dataclass(frozen=True, slots=True)
class Profile:
    """The profile a recording is judged against, and where each half came from."""

    px4: PX4Profile = DEFAULT_PX4
    vehicle: str = DEFAULT_VEHICLE
    px4_detected: bool = False
    """Known, not assumed (from the recording, or set by the user: see ``px4_forced``)."""
    vehicle_detected: bool = False
    px4_release: str | None = None
    """The exact release the recording names, where it names one."""
    px4_forced: bool = False
    """Set by the user (``--px4``, the config file), whatever the recording says."""
    vehicle_forced: bool = False
    px4_note: str | None = None
    """Why this record and not another that reports the same version (main and 1.18)."""

    @property
    def detected(self) -> bool:
        """Both halves read from the recording (not set by the user, not assumed)."""
        return self.px4_source == self.vehicle_source == "recording"

    @property
    def px4_source(self) -> str:
        """Where the PX4 profile came from: ``user``, ``recording`` or ``default``."""
        return _source(self.px4_forced, self.px4_detected)

    @property
    def vehicle_source(self) -> str:
        return _source(self.vehicle_forced, self.vehicle_detected)

    @property
    def release(self) -> Release:
        """The release record of ``px4`` (look it up once, where a model or check is built)."""
        return releases.get(self.px4)

    @property
    def is_rover(self) -> bool:
        return is_rover(self.vehicle)

    def describe(self) -> str:
        px4 = f"PX4 {self.px4}"
        named = px4_profile_for(self.px4_release) if self.px4_release else None
        if named == self.px4 or (named and self.release.reports_as == named):
            px4 += f" ({self.px4_release})"
        px4 += f" {SOURCE_WORDS[self.px4_source]}"
        if self.px4_forced and named not in (None, self.px4):
            px4 += f" (the recording says {self.px4_release})"
        if self.px4_note:
            px4 += f" ({self.px4_note})"
        return f"{px4}, {self.vehicle} {SOURCE_WORDS[self.vehicle_source]}"


SOURCE_WORDS = {"user": "set by the user", "recording": "detected", "default": "assumed"}
"""How a report words each ``Profile.px4_source`` / ``vehicle_source``."""


def _source(forced: bool, known: bool) -> str:
    if forced:
        return "user"
    return "recording" if known else "default"


# MAVLink MAV_TYPE -> vehicle type (rovers cannot be told apart from MAV_TYPE alone).
MAV_TYPE_VEHICLE: dict[int, str] = {
    1: "fw",
    2: "mc",
    3: "mc",
    4: "mc",
    10: "rover-differential",
    13: "mc",
    14: "mc",
    15: "mc",
    19: "vtol",
    20: "vtol",
    21: "vtol",
    22: "vtol",
    23: "vtol",
    24: "vtol",
    25: "vtol",
    29: "mc",
}

# vehicle_status.vehicle_type -> vehicle type (is_vtol checked first by callers).
ROVER_ASSUMED = "rover-differential"
"""The rover kind taken where a recording says "rover" but not which kind (``vehicle_type``
3, rover topics): the kind ``--vehicle rover`` also means."""

PX4_VEHICLE_TYPE: dict[int, str] = {1: "mc", 2: "fw", 3: ROVER_ASSUMED}
