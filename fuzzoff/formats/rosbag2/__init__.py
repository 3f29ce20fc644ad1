"""ROS 2 bag folders (sqlite3 or MCAP storage): reader, metadata.yaml checks, salvage, writer."""
