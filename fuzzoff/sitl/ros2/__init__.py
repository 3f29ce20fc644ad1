"""PX4 driven over its ROS 2 bridge (uXRCE-DDS): a DDS client, a bag recorder, a flight.

PX4's ``uxrce_dds_client`` talks to the Micro XRCE-DDS Agent, which puts PX4's topics on DDS;
a ROS 2 node is one more DDS participant. Here that participant is the ``cyclonedds`` package
(the ``ros2live`` extra), with the px4_msgs types of the release built from its ``.msg`` files,
so no ROS 2 install is needed. Everything runs inside a private network namespace whose only
interface is loopback (``netns``): DDS discovers its peers by multicast.

- ``names``: the DDS names of a release's topics and types;
- ``dds``: the px4_msgs types as DDS types, readers and writers (imports cyclonedds);
- ``bag``: what was received, written as ``ros2 bag record`` writes it (rosbags' writer);
- ``example``: the behaviour of px4_ros_com's ``offboard_control`` example, and its hazards;
- ``rover``: a rover node driving with the rover setpoints (the ``rover_*`` programs);
- ``flight``: one PX4 boot, the agent, the recorder and the client (inside the namespace);
- ``netns``: starts ``flight`` inside ``unshare --net --mount``.
"""
