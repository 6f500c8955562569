"""Measured runs through the model: each run simulated with its own measured input.

This is the one place where a measurement becomes a simulation: identification's
output-error fits, validation, the diagnosis and its report all call
:func:`simulate_run`. The simulation is noise-free (the sensor offset of the model
included): a comparison never carries random noise of the model's own.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from landing_gear_sim.calibration.runs import ClassifiedRun, classified
from landing_gear_sim.calibration.wheel_angle import (
    brake_run_phases,
    free_rolling,
    has_brake_runout,
    measured_angle_rad,
    run_phases,
)
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.elements import valve_static_pressure
from landing_gear_sim.model.integrate import SimulationResult, simulate
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import at_static_load, load_taken_at, rim_speed_m_s
from landing_gear_sim.model.scenario import Scenario, logged_to_held
from landing_gear_sim.model.sensors import SensorModel
from landing_gear_sim.processes import map_threads
from msg_tools.run import Run

CHANNELS: dict[str, str] = {
    "pressure_pa": "brake pressure [Pa]",
    "wheel_speed_rad_s": "wheel speed [rad/s]",
    "flywheel_speed_rad_s": "flywheel speed [rad/s]",
    "vertical_load_n": "vertical load [N]",
    "longitudinal_force_n": "longitudinal force [N]",
}
"""Measured channels a simulation is compared on (Run fields), with their label."""
ACTUATOR_CHANNELS = ("pressure_pa",)
"""An actuator-only run carries information on the pressure alone."""
LOWEST_SIM_SPEED_M_S = 1.0  # below this slip is ill-defined; the rig stops at 3 m/s
INITIAL_SPEED_SAMPLES = 20  # the initial speed is the mean of this many samples
STATIC_LOAD_SAMPLES = 100  # fewer free-rolling samples: the model's static load is kept
SAME_LOAD = 0.01  # a run within 1 % of the model's static load is at the device's set point


def channels_of(run: ClassifiedRun) -> tuple[str, ...]:
    """The channels that carry information in ``run``."""
    return tuple(CHANNELS) if run.braking else ACTUATOR_CHANNELS


def scenario_for_run(run: ClassifiedRun, params: RigParameters,
                     wheel_angle_rad: np.ndarray | None = None) -> Scenario:
    """The measured run's input as a scenario: its current, its initial speed, its timing
    (and the wheel's measured angle, for a disc's run-out, when given)."""
    initial = float(np.mean(rim_speed_m_s(params, run.flywheel_speed_rad_s[
        :INITIAL_SPEED_SAMPLES])))
    contact = run.braking
    current = logged_to_held(run.command_a)
    return Scenario(run.name, current, run.rate_hz, contact,
                    initial if contact else 0.0, LOWEST_SIM_SPEED_M_S if contact else 0.0,
                    "measured input", wheel_angle_rad=wheel_angle_rad,
                    settled_start=starts_settled(run, params, float(current[0])))


START_SAMPLES = 20  # the first samples that say whether a log starts at rest or mid-hold


def starts_settled(run: Run, params: RigParameters, current_a: float) -> bool:
    """Whether ``run``'s pressure starts nearer the map's pressure for its first current than
    zero: a part of a run cut mid-hold does (started at rest its simulation was 18 bar off
    there), a sweep whose first sample commands a step does not (the rig starts at rest)."""
    static = float(valve_static_pressure(params.vector(), current_a))
    first = float(SensorModel.of(params).true_pressure(
        np.median(run.pressure_pa[:START_SAMPLES])))
    return static > 0.0 and abs(first - static) < abs(first)


GAIN = K.BRAKE_GAIN_N_M_PER_PA
DRIFT = K.BRAKE_GAIN_DRIFT_PER_RUN


def run_parameters(params: RigParameters, campaign_order: float) -> RigParameters:
    """The set a run at ``campaign_order`` (see ClassifiedRun) brakes with: k_b moved by
    ``brake.gain_drift_per_run`` per run from the middle run's (wear through a campaign)."""
    drift = params.number(DRIFT)
    if drift == 0.0 or campaign_order == 0.0:
        return params
    return params.replace({GAIN: params.number(GAIN) * (1.0 + drift * campaign_order)},
                          "run in the campaign")


def run_static_load_n(run: ClassifiedRun, params: RigParameters) -> float | None:
    """The static load the loading device held in ``run`` [N]: the mean of F_z + lift(v) in
    the free rolling before the brake acts (the load settled and the speed nearly steady, so
    the servo's lag is nil); None when the run has too little free rolling."""
    mask = free_rolling(run) if run.braking else np.zeros(len(run), dtype=bool)
    if mask.sum() < STATIC_LOAD_SAMPLES:
        return None
    speed = rim_speed_m_s(params, run.flywheel_speed_rad_s[mask])
    return float(np.mean(run.vertical_load_n[mask]
                         + load_taken_at(params, run.time_s[mask] - run.time_s[0], speed)))


def _at_run_load(params: RigParameters, run: ClassifiedRun) -> RigParameters:
    """The set with the loading device at the run's own static load (like its initial
    speed: a campaign may brake at several), the friction curve's reference load kept; the
    model's own when the run's is within SAME_LOAD of it (the estimate's few newtons of
    noise only perturbed the fits: a pressure slope moved by 4 %)."""
    load = run_static_load_n(run, params)
    model = params.number(K.LOADING_STATIC_LOAD_N)
    if load is None or abs(load - model) <= SAME_LOAD * model:
        return params
    return at_static_load(params, load, "the run's static load")


def simulate_run(run: Run, params: RigParameters) -> tuple[Run, SimulationResult]:
    """Simulate ``run`` with its measured current; the result on the run's (uniform, see
    :func:`~landing_gear_sim.calibration.runs.classified`) time base.

    If the model stops (speed below 1 m/s) before the measurement ends, the last
    simulated sample is held, so both have the same length, except the pressure: the
    valve goes on following the measured current; where the logger lost samples (see
    ClassifiedRun.compared) it holds the measurement, so nothing compares them. The
    touch-down time is the run's
    start, as in the rig procedure; the loading device holds the run's own static load. A
    wheel encoder that ripples with the wheel's angle, and a disc's run-out, act at the
    measured angle, with the run's own phase (see
    :mod:`~landing_gear_sim.calibration.wheel_angle`).
    """
    run = classified(run)
    params = _at_run_load(run_parameters(params, run.campaign_order), run)
    angle = followed = None
    if run.braking and SensorModel.of(params).ripples:
        params, angle = run_phases(params, run), measured_angle_rad(run)
    if run.braking and has_brake_runout(params):
        params, followed = brake_run_phases(params, run), measured_angle_rad(run)
    result = simulate(params, scenario_for_run(run, params, followed))
    simulated = result.to_run(
        wheel_angle_rad=None if angle is None else angle[:len(result.time_s)])
    n, m = len(run), len(simulated)
    take = np.minimum(np.arange(n), m - 1)
    fields = {name: getattr(simulated, name)[take] for name in CHANNELS}
    if m < n:
        fields["pressure_pa"] = result.sensed_pressure_to_end()[:n]
    if run.bridged is not None:  # not compared where the logger lost the rig
        lost = ~run.compared
        fields = {name: np.where(lost, getattr(run, name), values)
                  for name, values in fields.items()}
    return Run(name=run.name, source="simulation", time_s=run.time_s,
               current_a=run.current_a, **fields), result


def simulate_all(runs: Sequence[Run], params: RigParameters) -> list[Run]:
    """Every run simulated with its measured input, on its own time base (the runs side by
    side: the compiled simulation releases the GIL)."""
    return list(map_threads(lambda run: simulate_run(run, params)[0], runs))
