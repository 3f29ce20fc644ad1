"""Sent against received, for one flight over PX4's ROS 2 bridge (``fuzzoff lint BAG --with ULOG``).

The companion's bag holds what it sent (``/fmu/in``) and what it got back (``/fmu/out``), on the
host's clock; PX4's ULog holds what PX4 received and published, on PX4's clock. ``bag`` and
``ulog`` read the two, ``clock`` maps the host's clock onto PX4's (the bridge's time sync offset,
PX4's outputs as received), ``compare`` says per topic what was sent and never received, the
delivery latency, and PX4's status changes the companion never saw; ``report`` turns that into
OFB108 findings and terminal lines (docs/ros2.md, "Sent against received").
"""


class BridgeError(ValueError):
    """The two files cannot be compared (not one flight, unreadable, nothing to align by)."""
