"""Simulate measured runs with their own inputs and score the model per channel.

Fit % = 100·(1 − ‖y − ŷ‖/‖y − ȳ‖) on simulation (not one-step prediction), plus
RMSE and maximum error, per contract channel.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration.identify import brake_start_s, classify
from landing_gear_sim.model.integrate import SimulationResult, simulate
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import Scenario, logged_to_held
from msg_tools.io import is_uniform, resample
from msg_tools.run import Run

CHANNELS: dict[str, str] = {
    "pressure_pa": "brake pressure [Pa]",
    "wheel_speed_rad_s": "wheel speed [rad/s]",
    "flywheel_speed_rad_s": "flywheel speed [rad/s]",
    "vertical_load_n": "vertical load [N]",
    "longitudinal_force_n": "longitudinal force [N]",
}
ACTUATOR_CHANNELS = ("pressure_pa",)
LOWEST_SIM_SPEED_M_S = 1.0  # below this slip is ill-defined; the rig stops at 3 m/s


@dataclass(frozen=True)
class Score:
    """Agreement of one channel: fit [%], RMSE and max |error| in the channel's SI unit."""

    fit_percent: float
    rmse: float
    max_error: float


@dataclass(frozen=True)
class RunComparison:
    """A measured run, its simulation with the measured input, and the scores."""

    measured: Run
    simulated: Run
    kind: str
    scores: dict[str, Score]
    result: SimulationResult | None = None


def fit_percent(measured: np.ndarray, simulated: np.ndarray) -> float:
    """100·(1 − ‖y − ŷ‖/‖y − ȳ‖); 100 is perfect, can be negative."""
    spread = float(np.linalg.norm(measured - measured.mean()))
    if spread == 0.0:
        return float("nan")
    return 100.0 * (1.0 - float(np.linalg.norm(measured - simulated)) / spread)


def score(measured: np.ndarray, simulated: np.ndarray) -> Score:
    error = measured - simulated
    return Score(fit_percent(measured, simulated), float(np.sqrt(np.mean(error ** 2))),
                 float(np.max(np.abs(error))))


def scenario_for_run(run: Run, params: RigParameters) -> Scenario:
    """The measured run's input as a scenario: its current, its initial speed, its timing."""
    contact = not classify(run).startswith("actuator")
    initial = float(np.mean(run.flywheel_speed_rad_s[:20])) * params.number("flywheel.radius_m")
    return Scenario(run.name, logged_to_held(run.current_a), run.rate_hz, contact,
                    initial if contact else 0.0, LOWEST_SIM_SPEED_M_S if contact else 0.0,
                    "measured input")


def simulate_run(run: Run, params: RigParameters) -> tuple[Run, SimulationResult]:
    """Simulate ``run`` with its measured current; the result on the run's time base.

    If the model stops (speed below 1 m/s) before the measurement ends, the last
    simulated sample is held, so both have the same length, except the pressure: the
    valve goes on following the measured current. The touch-down time is the run's
    start, as in the rig procedure.
    """
    uniform = run if is_uniform(run, 1e-3) else resample(run, round(run.rate_hz))
    result = simulate(params, scenario_for_run(uniform, params))
    simulated = result.to_run()
    n, m = len(uniform), len(simulated)
    take = np.minimum(np.arange(n), m - 1)
    fields = {name: getattr(simulated, name)[take] for name in CHANNELS}
    if m < n:
        fields["pressure_pa"] = result.sensed_pressure_to_end()[:n]
    return Run(name=run.name, source="simulation", time_s=uniform.time_s,
               current_a=uniform.current_a, **fields), result


def compare(measured: Run, simulated: Run, kind: str | None = None) -> RunComparison:
    """Score ``simulated`` against ``measured`` on their common samples."""
    kind = kind or classify(measured)
    n = min(len(measured), len(simulated))
    channels = ACTUATOR_CHANNELS if kind.startswith("actuator") else tuple(CHANNELS)
    scores = {c: score(getattr(measured, c)[:n], getattr(simulated, c)[:n]) for c in channels}
    return RunComparison(measured, simulated, kind, scores)


def validate(runs: Sequence[Run], params: RigParameters) -> list[RunComparison]:
    """Simulate every run with its measured input and score it."""
    out = []
    for run in runs:
        simulated, result = simulate_run(run, params)
        comparison = compare(run, simulated)
        out.append(RunComparison(run, simulated, comparison.kind, comparison.scores, result))
    return out


def braking_window(run: Run, params: RigParameters) -> np.ndarray:
    """Samples from the brake application to where the rig is about to stop."""
    t = run.time_s - run.time_s[0]
    speed = run.flywheel_speed_rad_s * params.number("flywheel.radius_m")
    return (t >= brake_start_s(run) - run.time_s[0]) & (
        speed > params.number("rig_test.stop_speed_m_s") + 1.0)
