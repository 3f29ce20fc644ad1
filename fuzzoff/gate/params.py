"""PX4's defaults for the parameters the gate reads, per profile (gate.md#params).

Precedence (lowest to highest): these defaults, the recording's ``Parameter`` events, the
user's overrides (``--param`` / ``[tool.fuzzoff] params``).

``FUZZOFF_RC_PRESENT`` is not a PX4 parameter: it is fuzzoff's assumption about whether an RC
transmitter or joystick is connected, used only where the recording has no
``failsafe_flags.manual_control_signal_lost`` (1 = present, the default; 0 = none).
"""

from __future__ import annotations

from fuzzoff import releases
from fuzzoff.profiles import Profile
from fuzzoff.releases import PX4Profile

RC_PRESENT = "FUZZOFF_RC_PRESENT"

GATE_PARAMS: tuple[str, ...] = (
    "COM_OF_LOSS_T",
    "COM_OBL_ACT",
    "COM_OBL_RC_ACT",
    "COM_RCL_EXCEPT",
    "COM_POSCTL_NAVL",
    "NAV_RCL_ACT",
    "MAV_FWDEXTSP",
    "MAV_SYS_ID",
    "MAV_COMP_ID",
    "MPC_LAND_SPEED",
    "COM_DISARM_PRFLT",
    "COM_RC_OVERRIDE",
    "COM_RC_STICK_OV",
    "MAN_OVERRIDE_SPD",
    "COM_POS_FS_ACT",
    RC_PRESENT,
)


def default_params(px4: PX4Profile) -> dict[str, float]:
    """The defaults of ``px4`` (a profile name) for every parameter in ``GATE_PARAMS``: those
    every release shares, then the release's own (``Release.param_defaults``)."""
    own = releases.get(px4).param_defaults
    params: dict[str, float] = {
        "COM_OF_LOSS_T": own["COM_OF_LOSS_T"],
        "COM_OBL_RC_ACT": 0.0,
        "MAV_FWDEXTSP": 1.0,
        "MAV_SYS_ID": 1.0,
        "MAV_COMP_ID": 1.0,
        "MPC_LAND_SPEED": 0.7,
        "NAV_RCL_ACT": 2.0,
        "COM_RCL_EXCEPT": 0.0,
        "COM_POSCTL_NAVL": 0.0,
        # Auto-disarm of a vehicle that does not take off; fuzzoff reads it as take-off
        # evidence (gate/landed.py). Not read for legacy (0: no such inference).
        "COM_DISARM_PRFLT": own["COM_DISARM_PRFLT"],
        RC_PRESENT: 1.0,
    }
    params.update(own)  # and the parameters a release alone has (COM_OBL_ACT before 1.14)
    return params


def effective_params(
    profile: Profile, recorded: dict[str, float], overrides: dict[str, float]
) -> dict[str, float]:
    """Defaults < recorded < overrides."""
    return default_params(profile.px4) | recorded | overrides


def loss_timeout(px4: PX4Profile, params: dict[str, float]) -> float:
    """The time without keep-alive after which the signal counts as lost (sections 2.1-2.3)."""
    fixed = releases.get(px4).fixed_loss_s
    if fixed is not None:
        return fixed
    return max(0.0, float(params.get("COM_OF_LOSS_T", 1.0)))
