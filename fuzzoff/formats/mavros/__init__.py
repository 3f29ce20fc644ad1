"""The MAVROS vocabulary shared by ROS 1 and ROS 2 bags: mavros_msgs definitions, the frame
arithmetic, topics to the MAVLink setpoints MAVROS sends PX4, and their ROS 2 decoding."""
