"""ROS 2 MCAP files: reader, damage checks, indexed and streaming paths, time order, writer."""
