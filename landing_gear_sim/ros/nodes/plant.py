"""``plant`` node: wheel, tyre, gear walk, flywheel and the rig's sensors.

Lockstep (default): the plant publishes sample k (sensor topics stamped k·h, and
``/clock``), then advances to k+1 only when the actuator's pressure and the loading
device's force stamped (k+1)·h have arrived. A peer silent for ``timeout_s`` is
logged as lost; from then on its input is held (the brake pressure goes to
``safe_pressure_pa``) and the run goes on, so the recorder is still fed.
Real time: a wall-clock timer advances one step per period with the latest inputs; the
samples are stamped with the ROS time they are due (the run's start + k·h).

The run starts when every link is matched, every node of ``participants`` has said it
is linked, and every node the graph shows publishing brake commands (an outside
controller) reads the plant's samples through a matched link: a controller that joined
late would miss sample 0 and never answer. A run that cannot start in
``start_timeout_s`` is an error (exit 4), never a run without braking.
"""

from __future__ import annotations

import os
import time

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Vector3Stamped, WrenchStamped
from rclpy.publisher import Publisher
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import FluidPressure, JointState
from std_msgs.msg import String, UInt64

from landing_gear_sim.model.blocks import PlantBlock, SensorSample
from landing_gear_sim.ros.graph import (
    LOST_PEER_EXIT,
    NOT_STARTED_EXIT,
    TOPIC_CLOCK,
    TOPIC_HYDRAULIC,
    TOPIC_LOAD,
    TOPIC_READY,
    TOPIC_RUN_END,
)
from landing_gear_sim.ros.nodes.graph_node import (
    GraphNode,
    RunFinishedError,
    main_for,
    not_acknowledged,
)
from landing_gear_sim.ros.nodes.handshake import Handshake, read_ready
from landing_gear_sim.ros.nodes.parameters import declare, rig_and_run
from landing_gear_sim.ros.nodes.stamps import RunClock
from landing_gear_sim.ros.nodes.topics import DATA_QOS, LATCHED_QOS, outside_gaps
from msg_tools.contract import (
    ATMOSPHERE_PA,
    FRAMES,
    TOPIC_FLYWHEEL,
    TOPIC_PRESSURE,
    TOPIC_WHEEL,
    TOPIC_WRENCH,
)
from msg_tools.units import PA_PER_BAR

ACTUATOR, LOADING = "actuator", "loading_device"
LOST_CHUNK = 500  # steps per watchdog tick once every input is lost: keep the executor responsive
DISCOVERY_GRACE_S = 1.0  # linked this long before a start: another run's nodes are seen
# by then (under load a second rig had matched its own three nodes before discovery showed it
# the first run's, and started beside it)
SLOW_ACK_S = 1.0  # acknowledgements later than this after the end are a held-up reader: said


class PlantNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("plant")
        params, self._scenario, self._lockstep = rig_and_run(self)
        noise = declare(self, "sensor_noise", False, "add sensors.* noise to the outputs")
        seed = int(declare(self, "noise_seed", 0, "seed of the sensor noise", 0))
        self._timeout_s = float(declare(self, "timeout_s", 10.0,
                                        "lockstep: wait this long for a peer, then hold its input",
                                        0.0))
        self._safe_pa = float(declare(self, "safe_pressure_pa", 0.0,
                                      "brake pressure applied once the actuator is lost [Pa]",
                                      0.0))
        self._participants = {str(p) for p in declare(
            self, "participants", [""], "nodes whose 'linked' message the run waits for; "
            "any other node that publishes commands is waited for through the graph") if p}
        self._start_timeout_s = float(declare(
            self, "start_timeout_s", 60.0, "give up (exit 4) when the run could not start "
            "in this long [s]; 0: wait forever", 0.0))
        self._progress_s = float(declare(self, "progress_period_s", 5.0,
                                         "say how far the run is every this many seconds of "
                                         "wall time [s]; 0: never", 0.0))
        self._priority = int(declare(self, "realtime_priority", 10,
                                     "real time: SCHED_FIFO priority of the stepping thread "
                                     "(1-99; 0: leave the scheduling alone)", 0, 99))
        # compile the step functions before the run: in real time the first samples do not
        # wait (the loading device's first force came ~0.6 s late, the wheel rolled unloaded)
        PlantBlock(params, self._scenario).advance(0.0, 0.0)
        self._plant = PlantBlock(params, self._scenario,
                                 np.random.default_rng(seed) if noise else None)
        self._rate_hz = self._scenario.rate_hz
        self._run_clock = RunClock(self._scenario.step_s, 0 if self._lockstep else None)
        self._pending: dict[str, dict[int, float]] = {ACTUATOR: {}, LOADING: {}}
        self._latest = {ACTUATOR: 0.0, LOADING: 0.0}
        self._lost: set[str] = set()
        self._ready: set[str] = set()
        self._heard = 0  # ready messages, of any session
        self._linked = self._started = self._done = False
        self._linked_at = 0.0
        self._messages = _Messages()
        self._out = {topic: self.publisher(kind, topic) for topic, kind in (
            (TOPIC_CLOCK, Clock), (TOPIC_FLYWHEEL, JointState), (TOPIC_WHEEL, JointState),
            (TOPIC_PRESSURE, FluidPressure), (TOPIC_WRENCH, WrenchStamped))}
        self._end = self.publisher(UInt64, TOPIC_RUN_END, LATCHED_QOS)
        inputs = [self.subscription(FluidPressure, TOPIC_HYDRAULIC, self._on_pressure,
                                    DATA_QOS),
                  self.subscription(Vector3Stamped, TOPIC_LOAD, self._on_load)]
        self._ready_topic = self.subscription(String, TOPIC_READY, self._on_ready,
                                              LATCHED_QOS).topic_name
        self._handshake = Handshake(self, self._out, inputs, self._on_linked)
        self._created = self._last_progress = time.monotonic()
        self._wall_start = self._reported = 0.0
        self._published_at: list[float] = []  # real time: wall time of each step's sample
        self._lateness: list[float] = []  # real time: wake-up after the tick's time [s]
        self._busy: list[float] = []  # real time: time spent in a tick [s]
        self.create_timer(min(self._timeout_s / 4, 0.1), self._watchdog)
        mode = "lockstep" if self._lockstep else "real time"
        self.get_logger().info(f"{self._scenario.name}: up to {self._plant.n_steps} steps at "
                               f"{self._rate_hz:g} Hz, {mode}; waiting for "
                               f"{', '.join(sorted(self._participants)) or 'inputs'}")

    # --- start --------------------------------------------------------------------------
    def _on_ready(self, message: String) -> None:
        name, run_id = read_ready(message.data)
        self._heard += 1
        if run_id == self.run_id:
            self._ready.add(name)
            self._maybe_start()
        elif not self._started:
            self._refuse_foreign(name, run_id)

    def _refuse_foreign(self, name: str, run_id: str) -> None:
        """A node of another session shares this rig's namespace and domain (a second run,
        or a node left over from one): its messages would mix into this run. Not starting
        is the one safe answer; no run end is published, as that would end the other run."""
        self.get_logger().error(
            f"{name} of another run (session {run_id or 'none'}; this run's: "
            f"{self.run_id or 'none'}) is on this namespace and ROS_DOMAIN_ID: its messages "
            "would mix into this run; stop it, or start this rig in another --namespace "
            "or domain")
        self.exit_code = NOT_STARTED_EXIT
        raise RunFinishedError(self.get_name())

    def _on_linked(self) -> None:
        self._linked = True
        self._linked_at = time.monotonic()
        self._maybe_start()

    def _maybe_start(self) -> None:
        # every node announcing on this namespace heard first: a node of another session
        # whose ready message came after this session's had let a second run start
        if (self._started or not self._linked or not self._participants <= self._ready
                or time.monotonic() - self._linked_at < DISCOVERY_GRACE_S
                or self.count_publishers(self._ready_topic) > self._heard
                or outside_gaps(self, self._out)):
            return
        self._started = True
        self._wall_start = self._last_progress = self._reported = time.monotonic()
        if not self._lockstep:  # stamps are ROS time from here on
            self._run_clock.origin_ns = self.get_clock().now().nanoseconds
        self.get_logger().info("all links matched: run starts")
        self._publish(self._plant.sample())
        if not self._lockstep:
            # the ticks fall half a period after each step's due time: a wake-up up to
            # half a period late or early still takes exactly one step (with the phase
            # left to chance, ~3 % of the ticks took two steps or none)
            self._ask_realtime_scheduling()
            self._wall_start = time.monotonic() - 0.5 / self._rate_hz
            self.create_timer(1.0 / self._rate_hz, self._realtime_tick)

    def _ask_realtime_scheduling(self) -> None:
        """SCHED_FIFO for this thread: on 2 cores shared with four other nodes, a plant
        under the ordinary scheduler was preempted often enough to miss 1 ms at p99
        (measured: p99 period jitter 0.97-1.15 ms without, 0.14-0.34 ms with)."""
        if self._priority <= 0:
            return
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(self._priority))
        except (PermissionError, OSError, ValueError) as exc:
            self.get_logger().warning(
                f"real-time scheduling (SCHED_FIFO {self._priority}) refused ({exc}): it "
                "needs root, CAP_SYS_NICE or an rtprio limit; pacing may jitter under load")

    # --- inputs -------------------------------------------------------------------------
    def _on_pressure(self, message: FluidPressure) -> None:
        self._take(ACTUATOR, message.header.stamp, message.fluid_pressure - ATMOSPHERE_PA)

    def _on_load(self, message: Vector3Stamped) -> None:
        self._take(LOADING, message.header.stamp, message.vector.z)

    def _take(self, peer: str, stamp: Time, value: float) -> None:
        self._pending[peer][self._run_clock.step_of(stamp)] = value
        if self._lockstep:
            self._advance_lockstep()

    # --- stepping -----------------------------------------------------------------------
    def _advance_lockstep(self, limit: int | None = None) -> None:
        steps = 0
        while self._started and not self._done and (limit is None or steps < limit):
            target = self._plant.step_index + 1
            if any(target not in self._pending[p] and p not in self._lost for p in self._pending):
                return
            pressure = self._pending[ACTUATOR].pop(target, None)
            load = self._pending[LOADING].pop(target, None)
            self._step(self._safe_pa if pressure is None else pressure,
                       self._plant.load_n if load is None else load)
            steps += 1

    def _realtime_tick(self) -> None:
        woke = time.monotonic()
        due = int((woke - self._wall_start) * self._rate_hz)
        self._lateness.append(woke - self._wall_start
                              - (self._plant.step_index + 1.5) / self._rate_hz)
        while not self._done and self._plant.step_index < due:
            target = self._plant.step_index + 1
            self._step(self._in_force(ACTUATOR, target), self._in_force(LOADING, target))
            self._published_at.append(time.monotonic())
        self._busy.append(time.monotonic() - woke)

    def _in_force(self, peer: str, step: int) -> float:
        """Real time: the input stamped for ``step``, or the newest one due by then (late),
        or the one held; inputs stamped ahead wait for their step."""
        pending = self._pending[peer]
        due = [s for s in pending if s <= step]
        if due:
            self._latest[peer] = pending[max(due)]
            for s in due:
                del pending[s]
        return self._latest[peer]

    def _step(self, pressure_pa: float, load_n: float) -> None:
        self._plant.advance(pressure_pa, load_n)
        self._last_progress = time.monotonic()
        if 0 < self._progress_s <= self._last_progress - self._reported:
            self._report_progress()
        self._publish(self._plant.sample())

    def _report_progress(self) -> None:
        """How far the run is, in sim time and against the wall clock (a long lockstep
        run under load once printed nothing for a minute)."""
        self._reported = self._last_progress
        sim, most = (n / self._rate_hz for n in (self._plant.step_index, self._plant.n_steps))
        factor = sim / max(self._reported - self._wall_start, 1e-9)
        self.get_logger().info(f"sim {sim:.2f} s of up to {most:.2f} s "
                               f"({100 * sim / most:.0f} %), real-time factor {factor:.2f}")

    def _publish(self, sample: SensorSample) -> None:
        stamp = self._run_clock.stamp(sample.step)
        for topic, message in self._messages.fill(sample, stamp).items():
            self._out[topic].publish(message)
        if self._plant.finished():
            self._finish()

    def _finish(self) -> None:
        self._done = True
        samples = self._plant.step_index + 1
        wall = time.monotonic() - self._wall_start
        sim = samples / self._rate_hz
        self.get_logger().info(f"run ends after {samples} samples ({sim:.3f} s sim time) in "
                               f"{wall:.2f} s wall: real-time factor {sim / max(wall, 1e-9):.2f}")
        if len(self._published_at) > 2:
            self.get_logger().info(self._pacing_report())
        if self._lost:
            # the run went on so the bag is complete, but it is not the run that was asked
            self.exit_code = LOST_PEER_EXIT
            self.get_logger().error(f"run completed without input from "
                                    f"{', '.join(sorted(self._lost))} (held from the loss on)")
        self._end.publish(UInt64(data=samples))

    def _pacing_report(self) -> str:
        periods = np.diff(self._published_at)
        jitter = np.percentile(np.abs(periods - 1.0 / self._rate_hz), 99)
        late_p50, late_p99 = np.percentile(self._lateness, [50, 99]) * 1e3
        busy_p99 = np.percentile(self._busy, 99) * 1e3
        return (f"real-time pacing: p99 period jitter {jitter * 1e3:.3f} ms at the plant over "
                f"{periods.size} periods; timer wake-up late by p50 {late_p50:.3f} / "
                f"p99 {late_p99:.3f} ms; time in a tick p99 {busy_p99:.3f} ms")

    # --- faults -------------------------------------------------------------------------
    def _watchdog(self) -> None:
        if not self._started:
            self._maybe_start()  # the graph's other nodes show up without a message to us
            if not self._started:
                self._report_waiting()
            return
        silent_s = time.monotonic() - self._last_progress
        if self._done or not self._lockstep or silent_s < self._timeout_s:
            return
        target = self._plant.step_index + 1
        for peer in self._pending:
            if peer not in self._lost and target not in self._pending[peer]:
                self._lost.add(peer)
                held = (f"brake pressure set to the safe {self._safe_pa / PA_PER_BAR:g} bar"
                        if peer == ACTUATOR
                        else f"vertical force held at {self._plant.load_n:.0f} N")
                self.get_logger().error(f"no input from {peer} for {self._timeout_s:g} s at "
                                        f"t = {self._plant.step_index / self._rate_hz:.3f} s: "
                                        f"{held}, run continues")
        self._advance_lockstep(LOST_CHUNK)
        self._last_progress = time.monotonic() - self._timeout_s  # lost: no more waiting

    def _report_waiting(self) -> None:
        waited_s = time.monotonic() - self._created
        if 0 < self._start_timeout_s < waited_s:
            self.get_logger().error(f"the run could not start in {self._start_timeout_s:g} s: "
                                    f"{self._missing()}")
            self.exit_code = NOT_STARTED_EXIT
            self._end.publish(UInt64(data=0))  # the others leave too
            raise RunFinishedError(self.get_name())
        if time.monotonic() - self._last_progress > 5.0:
            self._last_progress = time.monotonic()
            self.get_logger().warning(f"still waiting ({waited_s:.0f} s): {self._missing()}")

    def _missing(self) -> str:
        return "; ".join(self._handshake.missing() + outside_gaps(self, self._out) + [
            f"{name} not linked" for name in sorted(self._participants - self._ready)])

    def pending(self) -> bool:
        return False  # close waits for the readers, by the plant's own rule

    def close(self) -> None:
        if not self.context.ok():  # stopped by a signal: the context is gone, nothing to flush
            return
        # nothing published is lost when the plant leaves; but a lost node never acknowledges,
        # and the wait lasted until DDS dropped it (16 s after a run with a stopped actuator)
        deadline = time.monotonic() + self._timeout_s if self._lost else None
        publishers = [*self._out.values(), self._end]
        soon = time.monotonic() + SLOW_ACK_S
        later = deadline is None or deadline > soon  # the wait may outlast SLOW_ACK_S
        waiting = not_acknowledged(self, publishers, soon if later else deadline)
        if waiting and self.context.ok() and later:
            # a starved or stopped reader holds the end up: say what it waits for
            self.get_logger().info(f"waiting for every reader of {_topics(waiting)} to "
                                   "acknowledge the run's last messages")
            waiting = not_acknowledged(self, waiting, deadline)
        if waiting and self.context.ok():  # not when a signal ended the wait
            self.get_logger().warning(
                f"leaving with {_topics(waiting)} not acknowledged by every reader "
                f"within {self._timeout_s:g} s (a lost node never acknowledges)")


def _topics(publishers: list[Publisher]) -> str:
    return ", ".join(p.topic_name for p in publishers)


class _Messages:
    """Reused output messages, filled from one sensor sample."""

    def __init__(self) -> None:
        self.clock = Clock()
        # the contract's frames: a bag whose messages carry them is read by fixed layouts
        self.wheel = JointState(name=[FRAMES[TOPIC_WHEEL]])
        self.wheel.header.frame_id = FRAMES[TOPIC_WHEEL]
        self.flywheel = JointState(name=[FRAMES[TOPIC_FLYWHEEL]])
        self.flywheel.header.frame_id = FRAMES[TOPIC_FLYWHEEL]
        self.pressure = FluidPressure()
        self.pressure.header.frame_id = FRAMES[TOPIC_PRESSURE]
        self.wrench = WrenchStamped()
        self.wrench.header.frame_id = FRAMES[TOPIC_WRENCH]

    def fill(self, sample: SensorSample, stamp: Time) -> dict[str, object]:
        self.clock.clock = stamp
        for message in (self.wheel, self.flywheel, self.pressure, self.wrench):
            message.header.stamp = stamp
        self.wheel.velocity = [sample.wheel_speed_rad_s]
        self.flywheel.velocity = [sample.flywheel_speed_rad_s]
        self.pressure.fluid_pressure = sample.pressure_pa + ATMOSPHERE_PA
        self.wrench.wrench.force.x = sample.longitudinal_force_n
        self.wrench.wrench.force.z = sample.vertical_load_n
        # the wheel first: it starts the longest chain (controller → actuator → plant)
        return {TOPIC_WHEEL: self.wheel, TOPIC_FLYWHEEL: self.flywheel,
                TOPIC_PRESSURE: self.pressure, TOPIC_WRENCH: self.wrench, TOPIC_CLOCK: self.clock}


main = main_for(PlantNode)

if __name__ == "__main__":
    main()
