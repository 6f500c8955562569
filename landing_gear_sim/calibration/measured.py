"""Measured runs through the model: each run simulated with its own measured input.

This is the one place where a measurement becomes a simulation: identification's
output-error fits, validation, the diagnosis and its report all call
:func:`simulate_run`. The simulation is noise-free (the sensor offset of the model
included): a comparison never carries random noise of the model's own.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

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
from landing_gear_sim.model.parameters import PerSet, RigParameters
from landing_gear_sim.model.plant import CHANNELS as PLANT_CHANNELS
from landing_gear_sim.model.quantities import at_static_load, load_taken_at, rim_speed_m_s
from landing_gear_sim.model.scenario import Scenario, logged_to_held
from landing_gear_sim.model.sensitivity import simulate_with_sensitivities
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


def channel_words(channel: str) -> str:
    """A channel as pages, figures and reasons name it ('wheel speed'; its code name, the
    Run field, stays in the JSON)."""
    return CHANNELS.get(channel, channel).split(" [")[0]


def channel_unit(channel: str) -> str:
    """A contract channel's SI unit, as its label gives it ('Pa')."""
    return CHANNELS[channel].split(" [")[1].rstrip("]")


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
    setup = _setup(run, params)
    result = simulate(setup.params, setup.scenario)
    return _as_logged(run, result, setup.angle), result


@dataclass(frozen=True)
class _Setup:
    """What a run is simulated with: the set (at the run's load, wear and phases), its
    scenario, and the measured wheel angle its encoder ripples at (None: no ripple)."""

    params: RigParameters
    scenario: Scenario
    angle: np.ndarray | None


def _setup(run: ClassifiedRun, params: RigParameters) -> _Setup:
    params = _at_run_load(run_parameters(params, run.campaign_order), run)
    angle = followed = None
    if run.braking and SensorModel.of(params).ripples:
        params, angle = run_phases(params, run), measured_angle_rad(run)
    if run.braking and has_brake_runout(params):
        params, followed = brake_run_phases(params, run), measured_angle_rad(run)
    return _Setup(params, scenario_for_run(run, params, followed), angle)


def _as_logged(run: ClassifiedRun, result: SimulationResult, angle: np.ndarray | None) -> Run:
    """The simulation as the run's logger reads it, on the run's samples (see
    :func:`simulate_run`)."""
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
               current_a=run.current_a, **fields)


def simulate_run_with_sensitivities(run: Run, params: RigParameters, keys: Sequence[str],
                                    spans: Sequence[float] | None = None
                                    ) -> tuple[Run, dict[str, np.ndarray]] | None:
    """:func:`simulate_run`'s run and each channel's derivatives with respect to ``keys``,
    (n, len(keys)) [the channel's unit per the key's], from one dual pass of the plant
    (:mod:`~landing_gear_sim.model.sensitivity`); None where they would not be the whole
    derivative: a run whose initial speed, or whose disc's phases, move with a key.

    What the keys change before the plant (the run's load, its wear) and the logger's read
    of the simulation (an offset, a channel out of step, a crosstalk, the valve's pressure
    after a stop) are cheap array arithmetic beside the simulation, affine or smooth: their
    part is a difference of that arithmetic alone, along the plant's derivatives and along
    each key. ``spans``: each key's scale (a fit's window), which sets the differences' steps
    where the key is at 0 (a slot's coefficient, an offset: a step of 1e-13 Pa was lost in
    the rounding of a pressure); default the key's size, or 1.
    """
    run = classified(run)
    keys = tuple(keys)
    setup = _setup(run, params)
    if run.braking and has_brake_runout(setup.params):
        return None  # the phases are fitted on the run under the set: no cheap difference
    steps = _steps(params, keys, spans)
    moved = [_setup(run, params.replace({k: params.number(k) + h}, "derivative"))
             for k, h in zip(keys, steps, strict=True)]
    if any(m.scenario.initial_speed_m_s != setup.scenario.initial_speed_m_s
           or m.scenario.settled_start != setup.scenario.settled_start for m in moved):
        return None
    base = setup.params.vector()
    seeds = np.stack([(m.params.vector() - base) / h for m, h in zip(moved, steps,
                                                                     strict=True)], axis=1)
    found = simulate_with_sensitivities(setup.params, setup.scenario, keys, seeds)
    logged = _as_logged(run, found.result, setup.angle)
    derivatives = {c: np.empty((len(run), len(keys))) for c in CHANNELS}
    for j, (m, h) in enumerate(zip(moved, steps, strict=True)):
        along = _logged_along(run, found.result, logged, found.tangents[:, :, j], setup.angle)
        own = _as_logged(run, replace(found.result, params=m.params), m.angle)
        for c in CHANNELS:
            derivatives[c][:, j] = along[c] + (getattr(own, c) - getattr(logged, c)) / h
    return logged, derivatives


_SETUP_STEP = 1e-7  # of a key's scale: the set-up and the logger are affine or smooth in it
_DATA_STEP = 1e-7  # of the simulated channels' size, along their derivatives
_READ = tuple(PLANT_CHANNELS.index(c) for c in ("pressure_pa", "wheel_speed_rad_s", "speed_m_s",
                                                "vertical_load_n", "longitudinal_force_n"))
"""The simulation's columns the logger reads (the flywheel's speed from the rim's)."""


def _steps(params: RigParameters, keys: tuple[str, ...], spans: Sequence[float] | None
           ) -> list[float]:
    """Each key's difference step, one the floats take exactly (a key's own seed is then 1
    to the bit)."""
    sizes = [abs(params.number(k)) for k in keys]
    scales = [max(size, span) for size, span in
              zip(sizes, spans if spans is not None else [1.0] * len(keys), strict=True)]
    return [(params.number(k) + _SETUP_STEP * scale) - params.number(k)
            for k, scale in zip(keys, scales, strict=True)]


def _logged_along(run: ClassifiedRun, result: SimulationResult, logged: Run,
                  tangent: np.ndarray, angle: np.ndarray | None) -> dict[str, np.ndarray]:
    """The logger's read (``logged`` of ``result``) of the simulation's derivative
    ``tangent`` (n, N_CHANNELS), the set held: a difference along it, with a step the
    rounding of the channels it reads does not swallow."""
    read = list(_READ)
    size = np.max(np.abs(result.data[:, read]), axis=0)
    reach = np.max(np.abs(tangent[:, read]), axis=0)
    moving = reach > 0.0
    if not np.any(moving):
        return {c: np.zeros(len(run)) for c in CHANNELS}
    step = _DATA_STEP * float(np.min(np.maximum(size[moving], 1e-300) / reach[moving]))
    moved = _as_logged(run, replace(result, data=result.data + step * tangent), angle)
    return {c: (getattr(moved, c) - getattr(logged, c)) / step for c in CHANNELS}


def simulate_all(runs: Sequence[Run], params: RigParameters) -> list[Run]:
    """Every run simulated with its measured input, on its own time base (the runs side by
    side: the compiled simulation releases the GIL)."""
    return list(map_threads(lambda run: simulate_run(run, params)[0], runs))


class Simulations(PerSet[list[Run]]):
    """The ``runs`` simulated under each model asked for, each model once (the diagnosis's
    extension read its search's model and the verdict read it again: a pass of the campaign
    simulated twice)."""

    def __init__(self, runs: Sequence[Run]) -> None:
        super().__init__(lambda model: simulate_all(runs, model))
