"""Benchmark of the ROS 2 node graph: lockstep real-time factor and real-time pacing.

Run: ``make bench`` (or ``python bench/graph.py``). Every node in its own process,
as ``landing-gear-sim rig`` starts them (plant, actuator, loading device, profile,
recorder). Prints ratios against the issue's targets and against a bare-rclpy
two-process ping-pong measured in the same run (the floor any graph here sits on).
Targets are reported, never asserted.
"""

from __future__ import annotations

import contextlib
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"  # DDS never leaves this machine
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))

RATES_HZ = (100, 250, 500, 1000)
TARGET_RTF = {500: 2.0, 1000: 1.0}
LOCKSTEP_SIM_S = 6.0
REALTIME_RATE_HZ, REALTIME_S = 500, 30.0
PING_PONG_S = 5.0


def _rig(*args: str, **overrides: float) -> subprocess.CompletedProcess:
    sets = [a for key, value in overrides.items() for a in ("--set", f"{key}={value}")]
    return subprocess.run([sys.executable, "-m", "landing_gear_sim", "rig", *args, *sets],
                          capture_output=True, text=True, timeout=900)


def lockstep_rtf(rate_hz: float, folder: Path, *extra: str) -> float:
    """Real-time factor of one lockstep braking run, as the plant measures it."""
    bag = folder / f"lockstep_{rate_hz:g}{''.join(extra)}"
    done = _rig("--profile", "osc-low", "--rate", str(rate_hz), "--bag", str(bag), *extra,
                **{"rig_test.brake_start_s": 0.3, "rig_test.max_duration_s": LOCKSTEP_SIM_S})
    found = re.search(r"real-time factor ([0-9.]+)", done.stderr)
    if done.returncode != 0 or not found:
        raise RuntimeError(done.stderr[-2000:])
    return float(found.group(1))


def realtime_periods(duration_s: float) -> tuple[float, float, float]:
    """Fraction of periods published (from the first one heard to the last), p99 period
    jitter [s] seen by a subscriber and at the plant (publish times, its own log)."""
    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState

    from landing_gear_sim.ros.nodes.graph_node import spin
    from msg_tools.contract import TOPIC_WHEEL

    rclpy.init()
    node = rclpy.create_node("bench_listener", start_parameter_services=False)
    arrivals: list[float] = []
    stamps: list[float] = []

    def heard(message: JointState) -> None:
        arrivals.append(time.monotonic())
        stamps.append(message.header.stamp.sec + message.header.stamp.nanosec * 1e-9)

    node.create_subscription(JointState, TOPIC_WHEEL, heard,
                             QoSProfile(depth=5000, reliability=ReliabilityPolicy.RELIABLE))
    graph = subprocess.Popen(
        [sys.executable, "-m", "landing_gear_sim", "rig", "--profile", "sweep", "--duration",
         str(duration_s), "--clock", "realtime", "--no-bag", "--rate", str(REALTIME_RATE_HZ)],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    left: list[float] = []

    def watch() -> None:
        if graph.poll() is not None and not left:
            left.append(time.monotonic())
        if left and time.monotonic() > left[0] + 2.0:  # drained what was still queued
            raise _DoneError

    node.create_timer(0.1, watch)
    with contextlib.suppress(_DoneError):
        spin(node)  # the nodes' own lean loop: rclpy's executor adds its own jitter
    node.destroy_node()
    rclpy.shutdown()
    at_plant = re.search(r"p99 period jitter ([0-9.]+) ms", graph.stderr.read())
    periods = np.diff(np.asarray(arrivals))
    jitter = np.abs(periods - 1.0 / REALTIME_RATE_HZ)
    # periods since the first one this listener heard (DDS matches it at its own pace)
    expected = round((stamps[-1] - stamps[0]) * REALTIME_RATE_HZ) + 1
    return (len(set(stamps)) / expected, float(np.percentile(jitter, 99)),
            float(at_plant.group(1)) * 1e-3 if at_plant else float("nan"))


class _DoneError(Exception):
    """The graph has left and its last messages are in."""


def ping_pong_rate(duration_s: float) -> float:
    """Round trips per second between two bare rclpy processes (Float64, reliable)."""
    echo = subprocess.Popen([sys.executable, __file__, "--echo"])
    try:
        import rclpy
        from std_msgs.msg import Float64

        rclpy.init()
        node = rclpy.create_node("bench_ping")
        out = node.create_publisher(Float64, "/bench/ping", 10)
        count = [0]
        node.create_subscription(Float64, "/bench/pong",
                                 lambda m: (count.__setitem__(0, count[0] + 1), out.publish(m)),
                                 10)
        while out.get_subscription_count() < 1 or node.count_publishers("/bench/pong") < 1:
            rclpy.spin_once(node, timeout_sec=0.05)
        time.sleep(0.5)
        out.publish(Float64(data=0.0))
        start = time.monotonic()
        while time.monotonic() - start < duration_s:
            rclpy.spin_once(node, timeout_sec=0.1)
        rate = count[0] / (time.monotonic() - start)
        node.destroy_node()
        rclpy.shutdown()
        return rate
    finally:
        echo.kill()
        echo.wait()


def _echo() -> None:
    import rclpy
    from std_msgs.msg import Float64

    rclpy.init()
    node = rclpy.create_node("bench_pong")
    out = node.create_publisher(Float64, "/bench/pong", 10)
    node.create_subscription(Float64, "/bench/ping", out.publish, 10)
    rclpy.spin(node)


def _row(name: str, value: str, target: str, ratio: float | None) -> None:
    verdict = "" if ratio is None else ("ok" if ratio >= 1.0 else "MISSED")
    ratio_text = "" if ratio is None else f"{ratio:8.2f}x"
    print(f"{name:44s} {value:>12s}   target {target:>9s} {ratio_text:>10s} {verdict}",
          flush=True)


def main() -> None:
    print("landing_gear_sim node-graph benchmark (5 processes; ratios > 1 beat the target)\n")
    floor = ping_pong_rate(PING_PONG_S)
    _row("bare rclpy 2-process ping-pong", f"{floor:.0f}/s", "-", None)
    with tempfile.TemporaryDirectory() as folder:
        rtfs = {}
        for rate in RATES_HZ:
            rtf = rtfs[rate] = lockstep_rtf(rate, Path(folder))
            target = TARGET_RTF.get(rate)
            _row(f"lockstep RTF at {rate} Hz exchange", f"{rtf:.2f}",
                 f">= {target:g}" if target else "-", rtf / target if target else None)
            print(f"{'':46s}{rtf * rate:.0f} steps/s = {rtf * rate / floor:.2f} x the ping-pong")
        bare = lockstep_rtf(1000, Path(folder), "--no-parameter-services")
        _row("lockstep RTF at 1000 Hz, no parameter services", f"{bare:.2f}", "-", None)
        print(f"{'':46s}with services / without: {rtfs[1000] / bare:.2f}")
    published, jitter_p99, at_plant = realtime_periods(REALTIME_S)
    _row(f"real time {REALTIME_RATE_HZ} Hz, {REALTIME_S:g} s: periods published",
         f"{100 * published:.2f} %", ">= 99.9 %", published / 0.999)
    _row("real time: p99 period jitter at a subscriber", f"{jitter_p99 * 1e3:.3f} ms",
         "<= 1 ms", 1e-3 / max(jitter_p99, 1e-9))
    _row("real time: p99 period jitter at the plant", f"{at_plant * 1e3:.3f} ms", "<= 1 ms",
         1e-3 / max(at_plant, 1e-9))


if __name__ == "__main__":
    if "--echo" in sys.argv:
        _echo()
    else:
        main()
