"""The sparse solver the diagnosis regresses on libraries of terms with (issues 14, 29)."""

from __future__ import annotations

import warnings

import numpy as np


def sparse_coefficients(x: np.ndarray, y: np.ndarray, intercept: bool = True) -> np.ndarray:
    """y ≈ c₀ + x c by the LARS lasso with its penalty chosen by BIC, on standardised
    columns: c in the units of x's columns (0 for a term left out), shape (k,). Without
    ``intercept`` y ≈ x c, the columns scaled by their rms (a constant column is a term)."""
    # imported here: scikit-learn costs ~1 s to import, which only a diagnosis needs to pay
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.linear_model import LassoLarsIC

    spread = x.std(axis=0) if intercept else np.sqrt(np.mean(x * x, axis=0))
    # a column the samples never fill (an owned term of rows a campaign lacks: the flywheel's
    # balance with no stop in it) is a term left out, not a NaN
    spread = np.where(spread > 0.0, spread, 1.0)
    with warnings.catch_warnings():  # LARS stopping early where the residues are small:
        warnings.simplefilter("ignore", ConvergenceWarning)  # the path so far is the answer
        if intercept:
            fit = LassoLarsIC(criterion="bic").fit((x - x.mean(axis=0)) / spread, y)
        else:
            fit = LassoLarsIC(criterion="bic", fit_intercept=False).fit(x / spread, y)
    return np.asarray(fit.coef_) / spread
