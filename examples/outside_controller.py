#!/usr/bin/env python3
"""An anti-skid controller of your own, outside the package, driving the rig graph.

It needs rclpy and sensor_msgs only. Start the rig without a controller of its own, then
this node in the rig's namespace (in either order; the rig waits for it, 60 s by default):

    landing-gear-sim rig --controller external --bag out/mine          # or clock realtime
    python3 examples/outside_controller.py --ros-args -r __ns:=/rig -p period_s:=0.01

The interface (docs/data-contract.md, "Outside controllers"):

- Read the plant's samples: ``wheel/joint_states`` and ``flywheel/joint_states``
  (``sensor_msgs/JointState``, speed in ``velocity[0]`` [rad/s]), both stamped with the
  sample's time t_k: sim time from 0 in lockstep, ROS time in real time.
- Publish ``brake/current_ref`` (``sensor_msgs/JointState``, ``name: [brake_valve]``,
  valve current [A] in ``effort[0]``) stamped with the **end** of the interval the current
  holds for: answering sample t_k for the next ``period_s``, stamp t_k + period_s. The
  valve steps by that time whatever your rate; in lockstep the plant waits for you each
  time your command runs out, so answer the sample at which it does.
- The run ends when ``run_end`` (``std_msgs/UInt64``, transient local) arrives. Before
  leaving, wait until your commands are acknowledged (``wait_for_all_acked``): DDS keeps a
  message only in its writer until every reader has it, and a recorder still catching up
  would otherwise lack your last commands (the rig then fails the run, naming the bag).

The law here is a plain bang-bang on wheel slip: from ``start_s`` on, the brake current
``current_a`` is applied while the wheel turns within ``slip`` of the speed it would have
rolling freely (the wheel/flywheel speed ratio just before ``start_s``), and released
below.
"""

from __future__ import annotations

import sys

import rclpy
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.task import Future
from sensor_msgs.msg import JointState
from std_msgs.msg import UInt64

DATA = QoSProfile(depth=5000, reliability=ReliabilityPolicy.RELIABLE)
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
LEAVE_WAIT = Duration(seconds=8.0)  # the longest to wait for the readers (a lost one never acks)


def nanoseconds(message: JointState) -> int:
    return message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec


class SlipController(Node):
    def __init__(self) -> None:
        super().__init__("outside_controller", namespace="rig")
        self.period_ns = round(self.declare_parameter("period_s", 0.01).value * 1e9)
        self.start_s = self.declare_parameter("start_s", 0.3).value
        self.current_a = self.declare_parameter("current_a", 0.6).value
        self.slip = self.declare_parameter("slip", 0.1).value
        self.origin_ns: int | None = None  # the first sample's stamp: the run's start
        self.next_ns = 0  # the stamp at which the last command runs out
        self.free_ratio = 0.0
        self.samples: dict[int, dict[str, float]] = {}
        self.unsent: list[JointState] = []
        self.out = self.create_publisher(JointState, "brake/current_ref", DATA)
        for joint in ("wheel", "flywheel"):
            self.create_subscription(JointState, f"{joint}/joint_states",
                                     lambda m, j=joint: self.on_sample(j, m), DATA)
        self.create_subscription(UInt64, "run_end", self.on_end, LATCHED)
        self.ended = Future()
        self.create_timer(0.01, self.flush)

    def on_sample(self, joint: str, message: JointState) -> None:
        stamp = nanoseconds(message)
        speeds = self.samples.setdefault(stamp, {})
        speeds[joint] = message.velocity[0]
        if len(speeds) < 2:
            return
        del self.samples[stamp]
        if self.origin_ns is None:
            self.origin_ns = self.next_ns = stamp
        if stamp >= self.next_ns:  # the last command runs out here: send the next
            self.next_ns = stamp + self.period_ns
            self.publish(self.law(stamp, speeds["wheel"], speeds["flywheel"]), self.next_ns)

    def law(self, stamp_ns: int, wheel_rad_s: float, flywheel_rad_s: float) -> float:
        if flywheel_rad_s <= 0:
            return 0.0
        if (stamp_ns - self.origin_ns) * 1e-9 < self.start_s:  # rolling freely still
            self.free_ratio = wheel_rad_s / flywheel_rad_s
            return 0.0
        if self.free_ratio <= 0:
            return 0.0
        ratio = wheel_rad_s / flywheel_rad_s / self.free_ratio
        return self.current_a if ratio > 1.0 - self.slip else 0.0

    def publish(self, current_a: float, until_ns: int) -> None:
        command = JointState(name=["brake_valve"], effort=[current_a])
        command.header.frame_id = "brake_valve"
        command.header.stamp.sec, command.header.stamp.nanosec = divmod(until_ns, 1_000_000_000)
        self.unsent.append(command)
        self.flush()

    def flush(self) -> None:
        """Send the commands held back until the actuator's link is matched at this end.

        DDS matches the two ends of a link each on its own, and this node may hear the
        plant's first sample before it has discovered the actuator: a command published
        then is lost, and in lockstep the run waits for it in vain (1 run in 3 did)."""
        readers = self.get_subscriptions_info_by_topic(self.out.topic_name)
        if (not any(reader.node_name == "actuator" for reader in readers)
                or self.out.get_subscription_count() < len(readers)):
            return
        while self.unsent:
            self.out.publish(self.unsent.pop(0))

    def on_end(self, message: UInt64) -> None:
        self.get_logger().info(f"run ended after {message.data} samples")
        self.ended.set_result(message.data)


def main() -> int:
    rclpy.init(args=sys.argv)
    node = SlipController()
    try:
        rclpy.spin_until_future_complete(node, node.ended)
        node.out.wait_for_all_acked(LEAVE_WAIT)  # the recorder may still lack the last ones
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl-C or SIGTERM: a clean stop
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
