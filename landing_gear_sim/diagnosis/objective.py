"""An output-error fit's objective: noise-scaled residuals of parameter sets, and its
forward-difference Jacobian with every (column, run) simulation side by side.

scipy's own finite differences simulate a Jacobian's columns one after another, each with
its runs side by side: a campaign's longest stop (3-4 times the others) held every column's
second core idle. Here a column's runs and the other columns' runs share the cores.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from landing_gear_sim.calibration.measured import simulate_run
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.processes import map_threads
from msg_tools.run import Run

Scales = dict[tuple[str, str], float]
DECIMATE = 2  # residual samples kept (the simulation itself runs at the full rate)
DIFF_STEP = 1e-4  # relative, as scipy's diff_step (the fits were tuned with it)


def scaled_error(runs: Sequence[Run], simulated: Sequence[Run], channels: Sequence[str],
                 scales: Scales) -> np.ndarray:
    """Simulation minus measurement over ``channels``, divided by the noise, decimated."""
    return np.concatenate([(getattr(sim, c) - getattr(run, c))[::DECIMATE]
                           / scales[(run.name, c)]
                           for run, sim in zip(runs, simulated, strict=True) for c in channels])


def scaled_residuals(runs: Sequence[Run], sets: Sequence[RigParameters],
                     channels: Sequence[str], scales: Scales) -> list[np.ndarray]:
    """:func:`scaled_error` of each parameter set of ``sets``, every (set, run) simulated
    side by side, each simulation reduced to its error as it comes (a Jacobian's
    simulated runs are never held all at once)."""
    def error(pair: tuple[RigParameters, Run]) -> np.ndarray:
        params, run = pair
        return scaled_error([run], [simulate_run(run, params)[0]], channels, scales)

    errors = map_threads(error, [(params, run) for params in sets for run in runs])
    n = len(runs)
    return [np.concatenate(errors[i * n:(i + 1) * n]) for i in range(len(sets))]


class Objective:
    """Residuals on the unit box (``residuals`` of many points at once) for
    ``least_squares``: ``fun`` one point, ``jac`` its forward differences (the residual at
    the point is the one ``fun`` just gave: the optimiser asks for a Jacobian where it
    evaluated last)."""

    def __init__(self, residuals: Callable[[Sequence[np.ndarray]], list[np.ndarray]]) -> None:
        self._residuals = residuals
        self._last: tuple[bytes, np.ndarray] | None = None

    def fun(self, u: np.ndarray) -> np.ndarray:
        (value,) = self._residuals([u])
        self._last = (u.tobytes(), value.copy())  # the optimiser may write into what it got
        return value

    def jac(self, u: np.ndarray) -> np.ndarray:
        f0 = self._last[1] if self._last and self._last[0] == u.tobytes() else self.fun(u)
        steps = forward_steps(u)
        points = [u.copy() for _ in range(u.size)]
        for j, point in enumerate(points):
            point[j] += steps[j]
        columns = self._residuals(points)
        # built by rows and transposed, as scipy's is: the solver's rounding follows the
        # layout, and the fits were tuned on scipy's path
        return np.array([(column - f0) / (point[j] - u[j])
                         for j, (column, point) in enumerate(zip(columns, points,
                                                                  strict=True))]).T


def forward_steps(u: np.ndarray) -> np.ndarray:
    """The steps of scipy's '2-point' differences with ``diff_step=DIFF_STEP`` on the unit
    box at ``u`` (>= 0): relative, a tiny absolute one where that vanishes, and backward
    where forward would leave the box (as ``scipy.optimize._numdiff`` takes them)."""
    steps = DIFF_STEP * np.abs(u)
    steps = np.where((u + steps) - u == 0, np.sqrt(np.finfo(float).eps) * np.maximum(1.0, u),
                     steps)
    below, above = u, 1.0 - u
    fitting = steps <= np.maximum(below, above)
    steps = np.where((u + steps > 1.0) & fitting, -steps, steps)
    return np.where(fitting, steps, np.where(above >= below, above, -below))
