"""An output-error fit's objective: noise-scaled residuals of parameter sets, every
(set, run) simulation side by side (the Jacobian's columns too:
:class:`~landing_gear_sim.calibration.differences.Objective`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from landing_gear_sim.calibration.differences import side_by_side, stacked
from landing_gear_sim.calibration.measured import (
    simulate_run,
    simulate_run_with_sensitivities,
)
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.processes import map_threads
from msg_tools.run import Run

Scales = dict[tuple[str, str], float]
DECIMATE = 2  # residual samples kept (the simulation itself runs at the full rate)


def scaled_error(runs: Sequence[Run], simulated: Sequence[Run], channels: Sequence[str],
                 scales: Scales) -> np.ndarray:
    """Simulation minus measurement over ``channels``, divided by the noise, decimated."""
    return np.concatenate([(getattr(sim, c) - getattr(run, c))[::DECIMATE]
                           / scales[(run.name, c)]
                           for run, sim in zip(runs, simulated, strict=True) for c in channels])


def scaled_residuals(runs: Sequence[Run], sets: Sequence[RigParameters],
                     channels: Sequence[str], scales: Scales) -> list[np.ndarray]:
    """:func:`scaled_error` of each parameter set of ``sets``, every (set, run) simulated
    side by side."""
    def error(params: RigParameters, run: Run) -> np.ndarray:
        return scaled_error([run], [simulate_run(run, params)[0]], channels, scales)

    return side_by_side(error, sets, runs)


def scaled_residuals_and_jacobian(runs: Sequence[Run], params: RigParameters,
                                  keys: Sequence[str], spans: Sequence[float],
                                  channels: Sequence[str], scales: Scales
                                  ) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`scaled_error` of ``params`` and its derivatives with respect to ``keys``
    (rows as the error's, a column per key; ``spans``: the keys' scales), every run's one
    dual pass of the plant side by side; None where a run's derivatives are not the plant's
    alone (see
    :func:`~landing_gear_sim.calibration.measured.simulate_run_with_sensitivities`)."""
    def one(run: Run) -> tuple[np.ndarray, np.ndarray] | None:
        found = simulate_run_with_sensitivities(run, params, keys, spans)
        if found is None:
            return None
        simulated, derivatives = found
        scale = [scales[(run.name, c)] for c in channels]
        error = scaled_error([run], [simulated], channels, scales)
        jacobian = np.concatenate([derivatives[c][::DECIMATE] / s
                                   for c, s in zip(channels, scale, strict=True)])
        return error, jacobian

    return stacked(map_threads(one, runs))
