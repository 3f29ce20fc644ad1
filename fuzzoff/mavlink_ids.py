"""MAVLink ids fuzzoff names, in one home: enum values of MAVLink's ``common.xml`` (and
``minimal.xml``) that the readers, writers, gate, checks and the SITL link compare or send.

The values are MAVLink's, fixed by the protocol; the names are the protocol's own. A module
that needs one imports it from here (it imports nothing, so every layer may).
"""

from __future__ import annotations

# MAV_AUTOPILOT
MAV_AUTOPILOT_INVALID = 8
MAV_AUTOPILOT_PX4 = 12

# MAV_TYPE
MAV_TYPE_QUADROTOR = 2
MAV_TYPE_GCS = 6

# MAV_COMPONENT
MAV_COMP_ID_AUTOPILOT1 = 1
MAV_COMP_ID_ONBOARD_COMPUTER = 191

# MAV_MODE_FLAG
MAV_MODE_FLAG_CUSTOM_MODE_ENABLED = 1
MAV_MODE_FLAG_SAFETY_ARMED = 128

# MAV_STATE
MAV_STATE_ACTIVE = 4

# MAV_LANDED_STATE
MAV_LANDED_STATE_UNDEFINED = 0
MAV_LANDED_STATE_ON_GROUND = 1

# MAV_SYS_STATUS_SENSOR
MAV_SYS_STATUS_SENSOR_RC_RECEIVER = 1 << 16
"""SYS_STATUS bit PX4 sets present and healthy while it has manual control (RC or a MAVLink
joystick: its ``manual_control_signal_lost`` is false)."""

# MAV_PARAM_TYPE
MAV_PARAM_TYPE_INT32 = 6
MAV_PARAM_TYPE_REAL32 = 9

# MAV_FRAME
MAV_FRAME_LOCAL_NED = 1
MAV_FRAME_LOCAL_ENU = 4
MAV_FRAME_BODY_NED = 8

# MAV_CMD
MAV_CMD_NAV_TAKEOFF = 22
MAV_CMD_NAV_VTOL_TAKEOFF = 84
MAV_CMD_DO_SET_MODE = 176
MAV_CMD_COMPONENT_ARM_DISARM = 400
MAV_CMD_SET_MESSAGE_INTERVAL = 511
MAV_CMD_REQUEST_MESSAGE = 512
MAV_CMD_DO_VTOL_TRANSITION = 3000
MAV_VTOL_STATE_MC, MAV_VTOL_STATE_FW = 3, 4
"""DO_VTOL_TRANSITION param1: the state to go to."""
