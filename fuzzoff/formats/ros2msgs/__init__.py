"""The px4_msgs vocabulary shared by the MCAP and ROS 2 bag formats: topic names, messages to
events (readers) and events to messages (writers); the definitions are in ``formats.px4_msgs``."""
