"""ROS 1 bags of MAVROS topics: reader, index checks, chunkwise and salvage reads, writer."""
