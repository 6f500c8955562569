"""Monte Carlo of closed-loop stops: a controller against the rig model over dispersions.

Each case is a rig test (touch-down, spin-up, braking to the stop) with its own surface
(dry, wet, snow, or a μ-jump from dry to wet or snow mid-stop), entry speed, static load
and, when an identification's 1-σ are given, the identified parameters drawn around their
values (normal, independent: the evidence file keeps the σ, not the correlations). Case
``i`` draws from its own generator seeded by (seed, i), so the result of a seed is the
same whether its cases run on one worker or many, in any order or chunking.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from antiskid.closed_loop import SURFACES, controller_settings
from antiskid.compiled import compiled_closed_loop
from antiskid.metrics import braking_metrics
from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.integrate import SimulationResult
from landing_gear_sim.model.parameters import SPECS, RigParameters
from landing_gear_sim.model.quantities import REFERENCE_LOAD, STATIC_LOAD, at_static_load

SURFACE_KINDS = ("dry", "wet", "snow", "jump")
"""``jump``: dry, then wet or snow below a speed drawn in ``jump_speed_m_s``."""
THETAS = ("theta1", "theta2", "theta3")
CHUNK = 25  # cases per task: ~1 s of work, so the scheduler's ~ms per task stays < 5 %
METRICS = ("braking_efficiency", "stopping_distance_m", "stopping_time_s", "lock_events",
           "lock_duration_s", "slip_max")
PERCENTILES = (1, 5, 50, 95, 99)
_SPEC = {spec.key: spec for spec in SPECS}


class MonteCarloError(LandingGearSimError):
    """The dispersions or the evidence they come from are not usable."""


@dataclass(frozen=True)
class Plan:
    """What to disperse and how: ranges are uniform [low, high], σ are 1-σ of a normal."""

    controller: str
    settings: Mapping[str, float] = field(default_factory=dict)
    seed: int = 1
    cases: int = 200
    surfaces: tuple[str, ...] = SURFACE_KINDS
    entry_speed_m_s: tuple[float, float] = (50.0, 70.0)
    load_factor: tuple[float, float] = (0.85, 1.15)
    jump_speed_m_s: tuple[float, float] = (15.0, 45.0)
    sigma: tuple[tuple[str, float], ...] = ()
    """(key, 1-σ) of identified parameters to draw around the base set's values."""

    def __post_init__(self) -> None:
        controller_settings(self.controller, self.settings)  # one clear error, early
        unknown = [s for s in self.surfaces if s not in SURFACE_KINDS]
        if unknown or not self.surfaces:
            raise MonteCarloError(f"surfaces must be among {', '.join(SURFACE_KINDS)}, got "
                                  f"{', '.join(unknown) or 'none'}")
        if self.cases < 1:
            raise MonteCarloError(f"cases must be >= 1, got {self.cases}")
        for name in ("entry_speed_m_s", "load_factor", "jump_speed_m_s"):
            low, high = getattr(self, name)
            if not 0.0 < low <= high:
                raise MonteCarloError(f"{name}: need 0 < low <= high, got {low}, {high}")
        bad = [key for key, _ in self.sigma if key not in _SPEC]
        if bad:
            raise MonteCarloError(f"sigma: unknown parameter {bad[0]!r}")

    def fingerprint(self, base: RigParameters) -> str:
        """Short hash of the plan and the base set: a journal entry of another plan is
        never taken for one of this plan."""
        text = json.dumps([asdict(self), base.vector().tolist()], sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:10]


@dataclass(frozen=True)
class Case:
    """One drawn stop: its label, the overrides of the base set, the drawn quantities."""

    index: int
    surface: str
    entry_speed_m_s: float
    load_factor: float
    jump_speed_m_s: float
    overrides: Mapping[str, float]

    def rig(self, base: RigParameters) -> RigParameters:
        return base.replace(dict(self.overrides), f"Monte Carlo case {self.index}")

    @property
    def name(self) -> str:
        return f"case-{self.index:05d}-{self.surface}"


def _static_load(base: RigParameters, factor: float) -> dict[str, float]:
    """The drawn static load, the friction curve's reference load kept at the base's."""
    loaded = at_static_load(base, factor * base.number(STATIC_LOAD))
    return {key: loaded.number(key) for key in (STATIC_LOAD, REFERENCE_LOAD)}


def draw_case(base: RigParameters, plan: Plan, index: int) -> Case:
    """Case ``index`` of ``plan``: a function of (seed, index) only."""
    rng = np.random.default_rng([plan.seed, index])
    surface = str(plan.surfaces[rng.integers(len(plan.surfaces))])
    speed = float(rng.uniform(*plan.entry_speed_m_s))
    factor = float(rng.uniform(*plan.load_factor))
    overrides = _drawn_parameters(base, plan.sigma, rng)
    overrides[K.RIG_TEST_INITIAL_SPEED_M_S] = speed
    overrides |= _static_load(base, factor)
    jump = math.nan
    if surface == "jump":
        after = str(rng.choice(sorted(SURFACES)))
        jump = float(rng.uniform(*plan.jump_speed_m_s))
        overrides[K.FRICTION_CHANGE_SPEED_M_S] = jump
        overrides |= {f"friction.after_{t}": v for t, v in zip(THETAS, SURFACES[after],
                                                                    strict=True)}
        surface = f"jump-{after}"
    elif surface != "dry":
        overrides |= {f"friction.{t}": v for t, v in zip(THETAS, SURFACES[surface],
                                                           strict=True)}
    return Case(index, surface, speed, factor, jump, overrides)


def _drawn_parameters(base: RigParameters, sigma: Sequence[tuple[str, float]],
                      rng: np.random.Generator) -> dict[str, float]:
    """Each parameter drawn from N(value, σ²), cut at ±3 σ and kept admissible."""
    drawn = {}
    for key, std in sigma:
        value = base.number(key)
        offset = float(np.clip(rng.standard_normal(), -3.0, 3.0)) * std
        new = value + offset
        spec = _SPEC[key]
        if not spec.signed:
            new = max(new, 0.05 * value if spec.positive else 0.0)
        drawn[key] = new
    return drawn


def simulate_case(base: RigParameters, plan: Plan, case: Case) -> SimulationResult:
    return compiled_closed_loop(case.rig(base), plan.controller, plan.settings)


def case_row(base: RigParameters, plan: Plan, index: int) -> dict[str, Any]:
    """The metrics of case ``index`` as a JSON-able row."""
    case = draw_case(base, plan, index)
    result = simulate_case(base, plan, case)
    row: dict[str, Any] = {"case": index, "surface": case.surface,
                           "entry_speed_m_s": case.entry_speed_m_s,
                           "load_factor": case.load_factor,
                           "jump_speed_m_s": None if math.isnan(case.jump_speed_m_s)
                           else case.jump_speed_m_s,
                           "stop_reason": result.stop_reason}
    try:
        metrics = braking_metrics(result.to_run(), result.params).to_dict()
    except LandingGearSimError as exc:  # e.g. no braking at all: a case, not a crash
        return row | {"error": str(exc)}
    return row | {key: metrics[key] for key in METRICS}


def chunk_task(base: RigParameters, plan: Plan, indices: Sequence[int]) -> dict[str, Any]:
    """One Dask task: the rows of the cases ``indices``, and the seconds they took."""
    started = time.perf_counter()
    rows = [case_row(base, plan, i) for i in indices]
    return {"cases": rows, "seconds": time.perf_counter() - started}


def chunks(plan: Plan) -> list[list[int]]:
    return [list(range(start, min(start + CHUNK, plan.cases)))
            for start in range(0, plan.cases, CHUNK)]


def summary(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Percentiles of every metric, the lock rate, and the same per surface."""
    good = [r for r in rows if "error" not in r]
    out: dict[str, Any] = {"cases": len(rows), "failed": len(rows) - len(good)}
    out |= _distribution(good)
    by_surface = {}
    for surface in sorted({r["surface"] for r in good}):
        by_surface[surface] = _distribution([r for r in good if r["surface"] == surface])
    out["by_surface"] = by_surface
    return out


def _distribution(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    if not rows:
        return {"n": 0}
    out: dict[str, Any] = {"n": len(rows),
                           "lock_rate": sum(r["lock_events"] > 0 for r in rows) / len(rows)}
    for key in METRICS:
        values = np.array([r[key] for r in rows], dtype=float)
        out[key] = {"mean": float(values.mean()),
                    **{f"p{q}": float(np.percentile(values, q)) for q in PERCENTILES}}
    return out


def worst_cases(rows: Sequence[dict[str, Any]], count: int) -> list[dict[str, Any]]:
    """The cases with wheel locks (most lock time first), then the least efficient ones:
    ``count`` in all."""
    good = [r for r in rows if "error" not in r]
    ranked = sorted(good, key=lambda r: (-r["lock_duration_s"], r["braking_efficiency"]))
    return ranked[:count]


def identification_sigma(evidence: Mapping[str, Any]) -> tuple[tuple[str, float], ...]:
    """(key, 1-σ) of the estimates of an identification evidence file
    (``<params>.identification.json``) that have a σ."""
    try:
        estimates = [(str(e["key"]), float(e["std"])) for e in evidence["estimates"]]
    except (KeyError, TypeError, ValueError) as exc:
        raise MonteCarloError(f"not an identification evidence file ({exc})") from None
    return tuple((key, std) for key, std in estimates
                 if key in _SPEC and math.isfinite(std) and std > 0.0)
