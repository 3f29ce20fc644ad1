"""The ROS 2 reading core the ``mcap`` and ``rosbag2`` formats share (neither imports the other).

A ROS 2 recording is one or more data files of one storage (an MCAP file, a SQLite database);
this package says which storage a file is from its content, and reads data files through
rosbags with fuzzoff's own per-connection decoding (``formats/ros2msgs``).
"""
