"""MCAP recordings of PX4 ROS 2 topics (formats.md 4): a one-file ROS 2 recording.

Read like a rosbag2 data file given on its own (``Rosbag2Source``), so the definitions, time
base, salvage and problems are the same for both formats.
"""

from __future__ import annotations

from fuzzoff.formats.rosbag2.reader import Rosbag2Source


class McapSource(Rosbag2Source):
    """A ``.mcap`` file (ROS 2, CDR).

    The happy path is rosbags' MCAP reader (the faster one, formats.md 4.5): chunk CRCs checked,
    only chunks holding PX4 channels decompressed, messages merged in time order chunk by chunk
    (bounded memory). A file without a valid footer or with a bad chunk goes through
    ``McapStream`` (``mcap``'s non-seeking ``StreamReader``, no whole-file time-order buffer),
    which skips the bad chunk and goes on, or keeps everything before a cut.
    """

    format = "mcap"
