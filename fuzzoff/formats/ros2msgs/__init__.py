"""The px4_msgs vocabulary shared by the MCAP and ROS 2 bag formats: definitions per release,
topic names, messages to events (readers) and events to messages (writers)."""
