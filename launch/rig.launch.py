"""``ros2 launch landing_gear_sim rig.launch.py [profile:=osc-low] [clock:=realtime] ...``

Thin on purpose: the nodes, their parameters and links come from
``landing_gear_sim.ros.graph.describe``, the same description ``landing-gear-sim rig``
starts without a ROS install. Arguments: see ``graph.LAUNCH_ARGUMENTS``.

A node that exits non-zero fails the run: launch shuts the graph down and returns 1
(an error raised in an event handler is launch's one way to a non-zero exit).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from landing_gear_sim.errors import GraphError
from landing_gear_sim.ros.graph import LAUNCH_ARGUMENTS, PACKAGE, describe, options_from_arguments
from landing_gear_sim.ros.launcher import parameter_arguments


def _nodes(context):
    values = {name: LaunchConfiguration(name).perform(context) for name in LAUNCH_ARGUMENTS}
    options, params_file = options_from_arguments(values)
    # the user's ROS_DOMAIN_ID and discovery settings reach the nodes untouched
    return [Node(package=PACKAGE, executable=node.name, name=node.name, output="screen",
                 namespace=node.namespace, parameters=[str(params_file)],
                 ros_arguments=parameter_arguments(node), remappings=list(node.remappings))
            for node in describe(options)]


def _fail_the_run(event, context):
    if event.returncode != 0:
        raise GraphError(f"{event.process_name} exited with code {event.returncode}: "
                                "the run failed")


def generate_launch_description():
    arguments = [DeclareLaunchArgument(name, default_value=default, description=text)
                 for name, (default, text) in LAUNCH_ARGUMENTS.items()]
    return LaunchDescription([*arguments, OpaqueFunction(function=_nodes),
                              RegisterEventHandler(OnProcessExit(on_exit=_fail_the_run))])
