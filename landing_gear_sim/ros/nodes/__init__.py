"""Thin rclpy adapters over the physics core, one executable and process per node.

``ros2 run landing_gear_sim <name>`` or ``python -m landing_gear_sim.ros.nodes.<name>``;
the graph they form is described once in :mod:`landing_gear_sim.ros.graph`.
"""
