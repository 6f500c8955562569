"""Anti-skid controllers as pure step functions, their closed loop and their metrics.

- :mod:`antiskid.threshold`: the industrial deceleration-threshold logic (paper Section II).
- :mod:`antiskid.slip`: gain-scheduled PI slip control with anti-windup.
- :mod:`antiskid.closed_loop`: a controller against the rig model, offline (same blocks as
  the node graph); :mod:`antiskid.metrics`: what a braking run achieved.
- :mod:`antiskid.node`: the ``antiskid_controller`` rclpy node (the only ROS import here).
"""
