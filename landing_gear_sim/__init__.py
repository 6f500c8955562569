"""landing_gear_sim: digital twin of an aircraft landing-gear anti-skid test rig.

The physics and analysis here never import ROS; ``landing_gear_sim.ros.nodes`` holds
the thin rclpy adapters.
"""

__version__ = "0.7.0"
