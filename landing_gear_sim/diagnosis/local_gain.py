"""The brake gain re-estimated locally (issue 14, part 2): per band of a physical variable
and along each run, relative to the model's own gain law.

On the samples where the wheel's torque balance measures the brake (as the consistency
checks use them), k_b is fitted through the origin of T = k_b P in each of ``BANDS``
equally populated bands of wheel speed, vertical load, pressure and absorbed brake energy,
and in ``WINDOW_S`` windows along each braking run; each estimate is divided by the gain
the model gives those samples (its slopes, fade and drift included), so a model that is
right reads 1 everywhere. A weighted straight line through the band estimates gives the
relative change over the range and its z (σ scaled up to the scatter about the line).
These are a look, not a verdict: the violations are judged by the consistency checks.
No plotting here (:mod:`landing_gear_sim.report.local_gain`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.statistics import (
    inverse_variance_weights,
    linear_std,
    weighted_least_squares,
)
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import PA_PER_BAR

BANDS = 8
WINDOW_S = 1.0
MIN_BAND_SAMPLES = 50
DECIMATE = 10  # the balance's samples are smooth: every 10th is plenty


@dataclass(frozen=True)
class LocalGain:
    """k_b over the model's gain in bands of ``variable`` (``centres`` in ``unit``), or
    along one run (``variable`` "time in run", ``run`` its name); arrays of shape (m,)."""

    variable: str
    unit: str
    run: str
    centres: np.ndarray
    ratio: np.ndarray
    std: np.ndarray
    change: float  # relative change of the line through them over the range [1]
    change_std: float

    @property
    def z(self) -> float:
        return abs(self.change) / self.change_std if self.change_std > 0 else 0.0

    def to_json(self) -> dict[str, object]:
        return {"variable": self.variable, "unit": self.unit, "run": self.run,
                "centres": self.centres.tolist(), "ratio": self.ratio.tolist(),
                "std": self.std.tolist(), "change": self.change, "change_std": self.change_std}

    def describe(self) -> str:
        return (f"k_b against {self.variable} ({self.run}): {100 * self.change:+.1f} % over "
                f"{self.centres.min():.3g}–{self.centres.max():.3g} {self.unit} "
                f"({self.z:.1f} σ)")


@dataclass(frozen=True)
class _Samples:
    torque: np.ndarray
    model: np.ndarray  # the model's brake torque for the same pressure
    variables: dict[str, np.ndarray]


def _samples(b: br.Braking, params: RigParameters) -> _Samples:
    torque, energy = br.torque_balance(b, params)
    m = np.flatnonzero(br.steady_braking_samples(b))[::DECIMATE]
    model = br.model_torque(b, params, energy, m)
    return _Samples(torque[m], model, {
        "wheel speed": b.wheel[m], "vertical load": b.load[m],
        "pressure": b.pressure[m] / PA_PER_BAR, "brake energy": energy[m] / 1e6,
        "time in run": b.time_s[m] - b.start_s})


VARIABLES: dict[str, str] = {"wheel speed": "rad/s", "vertical load": "N", "pressure": "bar",
                             "brake energy": "MJ"}


def local_gains(runs: Sequence[ClassifiedRun], params: RigParameters) -> list[LocalGain]:
    """Band estimates over the campaign for each of VARIABLES, then along each run."""
    per_run = _per_run(runs, params)
    if not per_run:
        return []
    pooled = _pooled([s for _, s in per_run])
    found = [g for variable, unit in VARIABLES.items()
             if (g := _banded(pooled, variable, unit, "campaign", _quantile_bands)) is not None]
    found.extend(g for name, s in per_run
                 if (g := _banded(s, "time in run", "s", name, _windows)) is not None)
    return found


def campaign_gain(runs: Sequence[ClassifiedRun], params: RigParameters, variable: str
                  ) -> LocalGain | None:
    """The band estimates over the campaign for ``variable`` (one of VARIABLES) alone (None:
    no braking run, or too few bands)."""
    per_run = _per_run(runs, params)
    if not per_run:
        return None
    return _banded(_pooled([s for _, s in per_run]), variable, VARIABLES[variable],
                   "campaign", _quantile_bands)


def _per_run(runs: Sequence[ClassifiedRun], params: RigParameters
             ) -> list[tuple[str, _Samples]]:
    return [(r.name, _samples(br.prepare(r, params), params)) for r in runs if r.braking]


def _pooled(samples: Sequence[_Samples]) -> _Samples:
    return _Samples(np.concatenate([s.torque for s in samples]),
                    np.concatenate([s.model for s in samples]),
                    {k: np.concatenate([s.variables[k] for s in samples])
                     for k in samples[0].variables})


Bands = Callable[[np.ndarray], list[np.ndarray]]


def _quantile_bands(values: np.ndarray) -> list[np.ndarray]:
    """Equally populated bands; a value many samples share (a constant-pressure run's
    level) is one band, not several."""
    edges = np.unique(np.quantile(values, np.linspace(0.0, 1.0, BANDS + 1)))
    count = max(edges.size - 1, 1)
    index = np.clip(np.searchsorted(edges, values, side="right") - 1, 0, count - 1)
    return [index == i for i in range(count)]


def _windows(values: np.ndarray) -> list[np.ndarray]:
    start = float(values.min()) if values.size else 0.0
    count = math.ceil((float(values.max()) - start) / WINDOW_S) if values.size else 0
    return [(values >= start + i * WINDOW_S) & (values < start + (i + 1) * WINDOW_S)
            for i in range(max(count, 1))]


def _banded(s: _Samples, variable: str, unit: str, run: str, bands: Bands
            ) -> LocalGain | None:
    values = s.variables[variable]
    rows = []
    for mask in bands(values):
        if np.count_nonzero(mask) < MIN_BAND_SAMPLES:
            continue
        design = s.model[mask][:, None]
        coef, *_ = np.linalg.lstsq(design, s.torque[mask], rcond=None)
        std = linear_std(design, s.torque[mask] - design @ coef, 1)[0]
        rows.append((float(np.mean(values[mask])), float(coef[0]), float(std)))
    if len(rows) < 3:
        return None
    centres, ratio, std = (np.array(column) for column in zip(*rows, strict=True))
    change, change_std = _line(centres, ratio, std)
    return LocalGain(variable, unit, run, centres, ratio, std, change, change_std)


def _line(centres: np.ndarray, ratio: np.ndarray, std: np.ndarray) -> tuple[float, float]:
    """Relative change over the range of a weighted line through the estimates, and its σ
    scaled up to the scatter about the line."""
    span = float(centres.max() - centres.min()) or 1.0
    design = np.column_stack([np.ones(centres.size), (centres - centres.mean()) / span])
    beta, covariance, chi2 = weighted_least_squares(
        design, ratio, inverse_variance_weights(ratio, std))
    inflation = max(1.0, chi2 / max(centres.size - 2, 1))
    level = abs(float(beta[0])) or 1.0
    return float(beta[1]) / level, math.sqrt(float(covariance[1, 1]) * inflation) / level
