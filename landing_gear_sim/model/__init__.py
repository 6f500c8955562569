"""The physics core: parameters, the rig's laws, the plant and its step functions.

Pure computation on SI quantities. No ROS, no files, no plots: everything above
(calibration, diagnosis, report, ros, the CLI) builds on these modules, and nothing
here imports them (``make lint`` checks the import contract).
"""
