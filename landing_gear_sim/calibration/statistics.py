"""Estimates and their honest uncertainty: least-squares covariances with residuals that
are correlated in time (simulation errors and integrated balances are smooth)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import OptimizeResult

from msg_tools.run import Run


@dataclass(frozen=True)
class Estimate:
    """One identified parameter: value and 1-σ uncertainty in SI, where it came from."""

    key: str
    value: float
    std: float
    runs: tuple[str, ...]
    method: str

    def to_json(self) -> dict[str, object]:
        return {"key": self.key, "value": self.value, "std": self.std, "method": self.method,
                "runs": list(self.runs)}


def lag_one_correlation(residual: np.ndarray) -> float:
    """Lag-1 autocorrelation ρ₁ of a residual (0 for a constant one)."""
    centred = residual - residual.mean()
    power = float(centred @ centred)
    return float(centred[1:] @ centred[:-1]) / power if power > 0 else 0.0


def effective_count(residual: np.ndarray) -> float:
    """Samples worth of independent information: n (1 − ρ₁)/(1 + ρ₁) (AR(1) residual)."""
    rho = float(np.clip(lag_one_correlation(residual), 0.0, 0.999))
    return max(len(residual) * (1 - rho) / (1 + rho), 2.0)


# a fit stops when a step lowers the cost by less than this fraction: the diagnosis' costs
# are ~1e4-1e5 (noise-scaled squares), so that is < 0.5 in χ², far below the ΔBIC threshold
# of 10 (scipy's default, 1e-8, went on for twice the steps to gain < 1)
FTOL = 1e-5
# nor once a step moves n_eff·ln(RSS), the unit of ΔBIC and of the held-out score, by less
# than this: where the residual is mostly structure (few effective samples: a fade tried
# before the valve's delay is in, at a cost of 3e6) FTOL alone let a fit crawl along a
# valley, 18 of its 34 steps for 0.3 % of its cost (0.4 in that unit)
NEGLIGIBLE_SCORE = 0.1


def negligible_gain(residual: np.ndarray) -> float:
    """``least_squares``' ftol for a fit starting at ``residual``: the relative fall of the
    cost a step must bring (FTOL, and NEGLIGIBLE_SCORE in n_eff·ln(RSS), d ln RSS being the
    cost's relative fall)."""
    return max(FTOL, NEGLIGIBLE_SCORE / effective_count(residual))


def correlation_inflation(residual: np.ndarray) -> float:
    """Variance factor (1 + ρ)/(1 − ρ) for residuals with lag-1 correlation ρ (AR(1)).

    Residuals of simulations and integrated balances are smooth; counting every
    sample as independent would claim far too small an uncertainty.
    """
    rho = lag_one_correlation(residual)
    return (1 + rho) / (1 - rho) if 0 < rho < 1 else 1.0


def covariance_std(result: OptimizeResult, n_params: int) -> np.ndarray:
    """1-σ from a least_squares result: σ² (JᵀJ)⁻¹, σ² from the (correlated) residuals."""
    return linear_std(result.jac, result.fun, n_params)


def linear_std(design: np.ndarray, residual: np.ndarray, n_params: int) -> np.ndarray:
    """1-σ of a least-squares fit with regressors ``design`` (n, k) and ``residual`` (n,)
    left over; shape (k,)."""
    sigma2 = float(residual @ residual) / max(residual.size - n_params, 1)
    cov = np.linalg.pinv(design.T @ design) * sigma2 * correlation_inflation(residual)
    return np.sqrt(np.clip(np.diag(cov), 0.0, None))


def cluster_std(design: np.ndarray, residual: np.ndarray, sizes: Sequence[int]) -> np.ndarray:
    """1-σ of a least-squares fit whose samples come in clusters (runs) of ``sizes``, in
    order: the sandwich (XᵀX)⁻¹ Σ_g X_gᵀ u_g u_gᵀ X_g (XᵀX)⁻¹ · G/(G − 1), so that an
    error shared within a run but not from run to run counts once per run; shape (k,)."""
    bread = np.linalg.pinv(design.T @ design)
    cuts = np.cumsum(sizes)[:-1]
    scores = np.array([x.T @ u for x, u in zip(np.split(design, cuts),
                                                np.split(residual, cuts), strict=True)])
    groups = len(sizes)
    cov = bread @ (scores.T @ scores) @ bread * groups / max(groups - 1, 1)
    return np.sqrt(np.clip(np.diag(cov), 0.0, None))


def inverse_variance_weights(values: np.ndarray, std: np.ndarray) -> np.ndarray:
    """1/σ² of each value; a σ of 0 (a value held fixed) is floored at 1e-9 of the values'
    scale, so it cannot weigh infinitely."""
    scale = float(np.mean(np.abs(values))) or 1.0
    return 1.0 / np.maximum(std, 1e-9 * scale) ** 2


def weighted_least_squares(design: np.ndarray, y: np.ndarray, weights: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray, float]:
    """y ≈ design β with weights 1/σ² (design (n, k), y and weights (n,)): β, its covariance
    for the σ as given, and χ² of the fit."""
    root = np.sqrt(weights)
    beta, *_ = np.linalg.lstsq(design * root[:, None], y * root, rcond=None)
    covariance = np.linalg.pinv((design * weights[:, None]).T @ design)
    return beta, covariance, float(np.sum(weights * (y - design @ beta) ** 2))


def run_weights(lengths: Sequence[int]) -> np.ndarray:
    """Weight on each run's residuals so that no run counts for more than a run of the
    median length, shape (len(lengths),): a 5-minute stop beside 10-s runs would otherwise
    decide the fit alone (issue 13). Shorter runs keep weight 1 (no noise inflated)."""
    n = np.asarray(lengths, dtype=float)
    return np.sqrt(np.minimum(1.0, np.median(n) / np.maximum(n, 1.0)))


def sample_weights(per_run: Sequence[np.ndarray]) -> np.ndarray:
    """Each sample's run weight (:func:`run_weights`), shape (total samples,)."""
    sizes = [values.size for values in per_run]
    return np.repeat(run_weights(sizes), sizes)


def input_timing_std_s(runs: Sequence[Run]) -> float:
    """1-σ of when the logged current's changes really happened [s]: the logger shows a
    change at the first sample after it, anywhere within a period (uniform: T/√12). A
    delay cannot be known better (200 Hz logs: 1.4 ms; their fit alone claimed 0.07 ms
    for a 2 ms error)."""
    return 1.0 / (max(r.rate_hz for r in runs) * math.sqrt(12.0))
