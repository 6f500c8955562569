"""The history of a rig: every campaign identified (and diagnosed), one table of the
parameters with their 1-σ in time order, and the trends and step changes in it.

Campaigns are taken in the order of their folder names (name them by test day, ISO
dates sort in time). A parameter's changes are judged against a constant: a straight
line in campaign order (wear) and a single step (a part replaced, at least ``MIN_SIDE``
campaigns on each side) are each fitted by weighted least squares; the better by BIC is
kept if it beats the constant by ``BIC_MARGIN`` and its size is significant at ``ALPHA``
(searched step positions counted). When the scatter the model leaves is larger than the
identification's σ, the σ are scaled up to it and the test is Student's t.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.stats

from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.statistics import (
    inverse_variance_weights,
    weighted_least_squares,
)
from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.io import campaign_sources, read_campaign

BIC_MARGIN = 10.0  # "very strong" (Kass & Raftery 1995)
ALPHA = 6e-5  # two-sided false-alarm rate per parameter: 4 σ of a normal
MIN_CAMPAIGNS = 4
PRIOR_DOF = 4
MIN_SIDE = 2  # campaigns on each side of a step: one deviant campaign is an outlier


def campaign_folders(paths: Sequence[Path]) -> list[Path]:
    """The campaigns among ``paths``: a folder with runs in it is one; a folder whose runs
    are all in sub-folders is a folder of campaigns (one per sub-folder). Sorted by name."""
    found: set[Path] = set()
    for path in map(Path, paths):
        sources = campaign_sources(path)
        if not sources:
            raise LandingGearSimError(f"{path}: no run files in it or its sub-folders")
        if any(s.parent == path for s in sources):
            found.add(path)
        else:
            found.update(path / s.relative_to(path).parts[0] for s in sources)
    return sorted(found, key=lambda p: (p.name, str(p)))


def campaign_task(folder: str, base: RigParameters, diagnosis: bool) -> dict[str, Any]:
    """Identify (and diagnose) one campaign: a JSON-able row. A campaign that cannot be
    read or identified gives a row with its error, not an exception."""
    started = time.perf_counter()
    row: dict[str, Any] = {"campaign": Path(folder).name, "path": folder}
    try:
        runs = read_campaign(Path(folder)).runs
        row["runs"] = len(runs)
        if diagnosis:
            from landing_gear_sim.diagnosis.diagnose import diagnose

            result = diagnose(runs, base)
            estimates = result.estimates
            row["verdict"] = result.verdict
            row["causes"] = [f.cause for f in result.findings]
        else:
            estimates = identify(runs, base, jackknife=False).estimates
    except LandingGearSimError as exc:
        return row | {"status": "failed", "error": str(exc),
                      "seconds": round(time.perf_counter() - started, 2)}
    return row | {"status": "ok", "values": {e.key: e.value for e in estimates},
                  "std": {e.key: e.std for e in estimates},
                  "seconds": round(time.perf_counter() - started, 2)}


@dataclass(frozen=True)
class Change:
    """A parameter that changed over the campaigns: a ``trend`` (``size`` relative change
    per campaign) or a ``step`` (``size`` relative jump from campaign ``at`` on)."""

    key: str
    kind: str
    size: float
    z: float
    at: str = ""

    def describe(self) -> str:
        if self.kind == "trend":
            return f"{self.key}: trend {100 * self.size:+.2f} % per campaign ({self.z:.0f} σ)"
        return f"{self.key}: step {100 * self.size:+.1f} % from {self.at} on ({self.z:.0f} σ)"

    def to_json(self) -> dict[str, Any]:
        return {"key": self.key, "kind": self.kind, "size": self.size, "z": self.z,
                "at": self.at}


@dataclass(frozen=True)
class _Fit:
    chi2: float
    k: int
    size: float
    size_std: float
    at: int = 0


def _candidates(y: np.ndarray, w: np.ndarray) -> list[_Fit]:
    n = len(y)
    ones = np.ones(n)
    _, _, chi2 = weighted_least_squares(ones[:, None], y, w)
    fits = [_Fit(chi2, 1, 0.0, 1.0)]
    beta, cov, chi2 = weighted_least_squares(np.column_stack([ones, np.arange(n)]), y, w)
    fits.append(_Fit(chi2, 2, beta[1], math.sqrt(cov[1, 1])))
    for at in range(MIN_SIDE, n - MIN_SIDE + 1):
        after = (np.arange(n) >= at).astype(float)
        beta, cov, chi2 = weighted_least_squares(np.column_stack([ones, after]), y, w)
        fits.append(_Fit(chi2, 3, beta[1], math.sqrt(cov[1, 1]), at))
    return fits


def parameter_change(key: str, campaigns: Sequence[str], values: np.ndarray,
                     std: np.ndarray) -> Change | None:
    """The trend or step of one parameter over ``campaigns`` (time order), or None."""
    if len(values) < MIN_CAMPAIGNS:
        return None
    w = inverse_variance_weights(values, std)
    fits = _candidates(values, w)
    n = len(values)
    best = min(fits, key=lambda f: f.chi2 + f.k * math.log(n))
    if best.k == 1:
        return None
    # the scatter the best model leaves says how large the σ really are (identification
    # σ of separate campaigns often understate the day-to-day spread), pooled with the σ
    # themselves worth PRIOR_DOF campaigns (a few campaigns' scatter is itself uncertain);
    # the test is Student's t on the pooled degrees of freedom
    dof = n - best.k + PRIOR_DOF
    inflation = max(1.0, (best.chi2 + PRIOR_DOF) / dof)
    looks = max(1, sum(f.k == best.k for f in fits))  # a step's position was searched for
    critical = float(scipy.stats.t.isf(ALPHA / (2 * looks), dof))
    gain = (fits[0].chi2 - best.chi2) / inflation - (best.k - 1) * math.log(n)
    z = abs(best.size) / (best.size_std * math.sqrt(inflation))
    if gain < BIC_MARGIN or z < critical:
        return None
    reference = abs(float(np.average(values[:best.at] if best.at else values,
                                     weights=w[:best.at] if best.at else w))) \
        or float(np.mean(np.abs(values))) or 1.0
    kind = "trend" if best.k == 2 else "step"
    return Change(key, kind, best.size / reference, z, campaigns[best.at] if best.at else "")


def changes(rows: Sequence[dict[str, Any]]) -> list[Change]:
    """Trends and step changes of every parameter identified in ``rows`` (ok rows, in time
    order). A campaign where a parameter has σ = 0 did not identify it (the fit held it,
    e.g. at a bound): it is left out of that parameter's series."""
    ok = [r for r in rows if r.get("status") == "ok"]
    keys = sorted({k for r in ok for k in r["values"]})
    found = []
    for key in keys:
        series = [(r["campaign"], r["values"][key], r["std"][key]) for r in ok
                  if r["std"].get(key, 0.0) > 0.0]
        if len(series) < MIN_CAMPAIGNS:
            continue
        names, values, std = zip(*series, strict=True)
        change = parameter_change(key, names, np.array(values), np.array(std))
        if change is not None:
            found.append(change)
    return found


def not_identified(rows: Sequence[dict[str, Any]]) -> dict[str, list[str]]:
    """Per parameter, the campaigns that did not identify it (σ = 0)."""
    held: dict[str, list[str]] = {}
    for r in rows:
        for key, std in r.get("std", {}).items():
            if std <= 0.0:
                held.setdefault(key, []).append(r["campaign"])
    return held


def table_columns(rows: Sequence[dict[str, Any]]) -> dict[str, list[Any]]:
    """The history as columns: campaign, status, verdict, runs, then value and 1-σ of every
    parameter (``<key>`` and ``<key>.std``, SI) in time order."""
    keys = sorted({k for r in rows for k in r.get("values", {})})
    columns: dict[str, list[Any]] = {
        "campaign": [r["campaign"] for r in rows],
        "status": [r["status"] for r in rows],
        "verdict": [r.get("verdict", "") for r in rows],
        "runs": [r.get("runs", 0) for r in rows],
    }
    for key in keys:
        columns[key] = [r.get("values", {}).get(key, math.nan) for r in rows]
        columns[f"{key}.std"] = [r.get("std", {}).get(key, math.nan) for r in rows]
    return columns
