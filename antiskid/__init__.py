"""Anti-skid controllers as pure step functions (threshold logic, slip control).

Filled by the closed-loop controller work; no ROS import here either.
"""
