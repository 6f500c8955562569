"""The ROS 2 node graph: its description (``graph``, no ROS import), the launcher
that starts it without a ROS install, and the rclpy node adapters (``nodes``)."""
