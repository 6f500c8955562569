"""A simulation's derivatives with respect to its parameters, from the plant itself.

:func:`simulate_with_sensitivities` runs the compiled run loop of
:mod:`landing_gear_sim.model.integrate` once with dual numbers (:mod:`.dual`): the same
step functions, the same branches, and beside every recorded channel its derivative with
respect to each chosen parameter, in the same pass. Its values are the plain simulation's
to the bit.

A(s)'s discrete matrices (the valve's ω_n, ζ, gain and delay) are closed forms of 3×3 matrix
exponentials computed before the loop: their derivatives are central differences of those
closed forms (no simulation; ~1e-9 relative), carried into the loop as the matrices'
tangents. A delay's whole steps are an integer: its derivative is that of the fraction of a
step, the path a plain simulation at that delay takes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import ACT_DELAY_STEPS, actuator_matrices
from landing_gear_sim.model.dual import LANES, call_dual, lanes_for
from landing_gear_sim.model.dual_arrays import DualRows, DualVector
from landing_gear_sim.model.integrate import STOP_REASONS, SimulationResult, run_kernel
from landing_gear_sim.model.parameters import INDEX, RigParameters
from landing_gear_sim.model.plant import CHANNELS, N_CHANNELS
from landing_gear_sim.model.scenario import Scenario

MATRIX_KEYS = (K.ACTUATOR_NATURAL_FREQUENCY_HZ, K.ACTUATOR_DAMPING_RATIO, K.ACTUATOR_GAIN,
               K.ACTUATOR_DELAY_S)
"""The parameters A(s)'s discrete matrices depend on."""
MATRIX_STEP = 1e-6  # relative step of the matrices' central differences
DELAY_STEP = 1e-6  # the delay's step, in steps of the run (within one fraction of a step)


@dataclass(frozen=True)
class Sensitivities:
    """A simulation and the derivatives of its channels: ``tangents[k, c, j]`` is
    d channel c / d ``keys[j]`` at sample k (the channel's SI unit per the key's)."""

    result: SimulationResult
    keys: tuple[str, ...]
    tangents: np.ndarray

    def of(self, channel: str) -> np.ndarray:
        """d ``channel`` / d each key, (n, len(keys))."""
        return self.tangents[:, CHANNELS.index(channel), :]


def simulate_with_sensitivities(params: RigParameters, scenario: Scenario,
                                keys: Sequence[str], seeds: np.ndarray | None = None
                                ) -> Sensitivities:
    """Simulate ``scenario`` with ``params`` and the derivatives of every channel with
    respect to ``keys`` (parameters of the set; a choice or a switch has none), in one
    compiled pass per :data:`~landing_gear_sim.model.dual.LANES`' largest count of keys.

    ``seeds`` (N_PARAMS, len(keys)): how each entry of the parameter vector moves with each
    key, where that is more than the key itself (a run's wear moves the brake gain with its
    rate); default the unit columns of the keys."""
    keys = tuple(keys)
    unknown = [k for k in keys if k not in INDEX]
    if unknown:
        raise ParameterError(f"no such parameter: {', '.join(unknown)}")
    vector = params.vector()
    if seeds is None:
        seeds = np.zeros((vector.size, len(keys)))
        for lane, key in enumerate(keys):
            seeds[INDEX[key], lane] = 1.0
    matrices = actuator_matrices(vector, scenario.step_s)
    moved = _matrix_derivatives(vector, matrices.size, scenario.step_s, seeds)
    lanes = lanes_for(len(keys))
    starts = range(0, max(len(keys), 1), lanes)
    passes = [_dual_pass(vector, matrices, scenario, seeds[:, start:start + lanes],
                         moved[:, start:start + lanes], lanes) for start in starts]
    rows, stop, values, _ = passes[0]
    # views: a stop's tangents are tens of megabytes, and a fit asks for one per run
    tangents = (passes[0][3][:rows, :, :len(keys)] if len(passes) == 1 else
                np.concatenate([t[:rows, :, :min(lanes, len(keys) - start)]
                                for (_, _, _, t), start in zip(passes, starts, strict=True)],
                               axis=2))
    result = SimulationResult(scenario, params, values[:rows], STOP_REASONS[stop])
    return Sensitivities(result, keys, tangents)


def prepare_kernels(params: RigParameters) -> None:
    """Compile (or load from numba's cache) the dual kernel of each lane count in this
    process: worker processes forked after it inherit them instead of each compiling its own
    (~20 s a count, once after an install)."""
    scenario = Scenario("prepare", np.zeros(2), 1000.0, False, 0.0, 0.0)
    for lanes in LANES:
        simulate_with_sensitivities(params, scenario, [K.ACTUATOR_GAIN] * lanes)


def _dual_pass(vector: np.ndarray, matrices: np.ndarray, scenario: Scenario,
               seeds: np.ndarray, matrix_seeds: np.ndarray, lanes: int
               ) -> tuple[int, int, np.ndarray, np.ndarray]:
    """One dual pass with the columns of ``seeds`` and ``matrix_seeds`` (at most ``lanes``;
    the rest zero): rows, stop code, values and tangents (n, N_CHANNELS, lanes)."""
    padding = ((0, 0), (0, lanes - seeds.shape[1]))
    seeds, matrix_seeds = np.pad(seeds, padding), np.pad(matrix_seeds, padding)
    n = scenario.current_a.size
    out = DualRows(np.empty((n, N_CHANNELS)), np.empty((n, N_CHANNELS, lanes)))
    angle = np.zeros(0) if scenario.wheel_angle_rad is None else scenario.wheel_angle_rad
    rows, stop = call_dual(run_kernel, DualVector(vector, seeds),
                           DualVector(matrices, matrix_seeds), scenario.current_a,
                           scenario.step_s, scenario.contact, scenario.initial_speed_m_s,
                           scenario.stop_speed_m_s, angle, out, scenario.settled_start)
    return int(rows), int(stop), out.values, out.tangents


def _matrix_derivatives(vector: np.ndarray, size: int, step_s: float, seeds: np.ndarray
                        ) -> np.ndarray:
    """How A(s)'s discrete matrices (``size`` entries) move along each column of ``seeds``,
    (size, columns)."""
    moved = np.zeros((size, seeds.shape[1]))
    for key in MATRIX_KEYS:
        along = seeds[INDEX[key]]
        if np.any(along != 0.0):
            moved += np.outer(_matrix_derivative(vector, step_s, key), along)
    return moved


def _matrix_derivative(vector: np.ndarray, step_s: float, key: str) -> np.ndarray:
    """d A(s)'s discrete matrices / d ``key``: central differences of their closed form; for
    the delay one-sided, on the side that keeps its whole steps (the matrices' layout
    follows them: a delay of exactly two steps and one a nanosecond shorter share none)."""
    index = INDEX[key]
    if key == K.ACTUATOR_DELAY_S:
        h = DELAY_STEP * step_s
        up = vector.copy()
        up[index] += h
        base = actuator_matrices(vector, step_s)
        moved = actuator_matrices(up, step_s)
        if moved[ACT_DELAY_STEPS] != base[ACT_DELAY_STEPS]:
            up[index] -= 2 * h
            h = -h
            moved = actuator_matrices(up, step_s)
        derivative = (moved - base) / h
    else:
        h = MATRIX_STEP * max(abs(vector[index]), 1.0)
        up, down = vector.copy(), vector.copy()
        up[index] += h
        down[index] -= h
        derivative = ((actuator_matrices(up, step_s) - actuator_matrices(down, step_s))
                      / (2 * h))
    derivative[ACT_DELAY_STEPS] = 0.0  # the delay's whole steps (an integer)
    return derivative
