"""MCAP recordings of PX4 ROS 2 topics (formats.md 4): a one-file ROS 2 recording.

Read by the ROS 2 reading core (``ros2.reader.Ros2Source``) that the ``rosbag2`` format's data
files are read by too, so the definitions, time base, salvage and problems are the same for both.
"""

from __future__ import annotations

from fuzzoff.formats.ros2.reader import Ros2Source


class McapSource(Ros2Source):
    """A ``.mcap`` file (ROS 2, CDR), whatever its name.

    The happy path is rosbags' MCAP reader (the faster one, formats.md 4.5): chunk CRCs checked,
    only chunks holding PX4 channels decompressed, messages merged in time order chunk by chunk
    (bounded memory). A file without a valid footer or with a bad chunk goes through
    ``McapStream`` (``mcap``'s non-seeking ``StreamReader``, no whole-file time-order buffer),
    which skips the bad chunk and goes on, or keeps everything before a cut.
    """

    format = "mcap"
