"""Identification of the rig model from a campaign (paper Sections IV-C, IV-D).

Each step uses the runs that carry its information and returns estimates with a
1-σ uncertainty and the runs they came from:

* runs are classified once from their signals (:mod:`~landing_gear_sim.calibration.runs`);
* valve static map and A(s) from the actuator-only runs
  (:mod:`~landing_gear_sim.calibration.actuator`);
* unloaded rolling radius, flywheel inertia and drag, brake gain (and fade) from the
  braking runs (:mod:`~landing_gear_sim.calibration.braking`);
* Burckhardt ϑ1..ϑ3 from slip and μ = F_x/F_z, refined by output error
  (:mod:`~landing_gear_sim.calibration.friction`).

No plotting here (see :mod:`landing_gear_sim.report`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration import flywheel
from landing_gear_sim.calibration.actuator import (
    FrfEstimate,
    fit_actuator_dynamics,
    fit_map_to_holds,
    fit_static_map,
)
from landing_gear_sim.calibration.friction import KEYS as FRICTION_KEYS
from landing_gear_sim.calibration.friction import fit_friction, refine_friction
from landing_gear_sim.calibration.plausibility import check_units, unit_notes
from landing_gear_sim.calibration.runs import (
    ClassifiedRun,
    RunKind,
    Setup,
    classify_all,
    fully_logged,
    select,
)
from landing_gear_sim.calibration.statistics import Estimate
from landing_gear_sim.errors import IdentificationError, ParameterError
from landing_gear_sim.model.parameters import SPEC_BY_KEY, RigParameters
from landing_gear_sim.processes import single_threaded_blas
from msg_tools.run import Run

Progress = Callable[[str], None]
"""Receives one line of progress at a time."""
ZERO_BOUND_FRACTION = 1e-3  # a direct-fit ϑ below this fraction of its prior sits on 0
MAX_THETA1 = 2.0  # μ never exceeds ϑ1; no tyre on a runway grips beyond ~1.3
MAX_SLIP_STIFFNESS = 200.0  # dμ/dλ at λ = 0, ϑ1 ϑ2 + ϑ3: tyres have 10-50


@dataclass(frozen=True)
class Identification:
    """Result of :func:`identify`: the calibrated set and the evidence behind it."""

    params: RigParameters
    estimates: tuple[Estimate, ...]
    classes: dict[str, RunKind]
    problems: tuple[str, ...] = ()
    frf: FrfEstimate | None = None
    not_identified: tuple[str, ...] = ()
    """Steps that were skipped or failed: their parameters keep the values of the base."""

    @property
    def complete(self) -> bool:
        return not self.not_identified

    def to_json(self, campaign: str, read_problems: Sequence[str] = ()) -> dict[str, object]:
        """The evidence file written beside the params (``<name>.identification.json``)."""
        return {"campaign": campaign,
                "classes": {name: kind.value for name, kind in self.classes.items()},
                "problems": [*read_problems, *self.problems],
                "not_identified": list(self.not_identified),
                "estimates": [e.to_json() for e in self.estimates]}


def _identified(estimate: Estimate) -> bool:
    """Whether the runs identify ``estimate``: a finite σ, no larger than the value for a
    quantity of one sign (a signed one, an offset or a slope, may be 0 within its σ)."""
    if not math.isfinite(estimate.std):
        return False
    spec = SPEC_BY_KEY.get(estimate.key)
    return spec is None or spec.signed or abs(estimate.std) <= abs(estimate.value)


class _Calibration:
    """The parameter set as the steps refine it, the estimates and the problems so far."""

    def __init__(self, base: RigParameters, say: Progress) -> None:
        self.params = base
        self.estimates: list[Estimate] = []
        self.problems: list[str] = []
        self.missed: list[str] = []
        self.frf: FrfEstimate | None = None
        self.say = say

    def adopt(self, new: Sequence[Estimate], start: bool = False) -> None:
        """Take the estimates ``new``, but one the runs cannot identify: a quantity of one
        sign whose σ exceeds its value keeps the value it had, with a note (a sweep cut
        before its first step had written ω_n 10.4 ± 1.6e7 Hz into the params file).
        ``start``: estimates a later step refines, all taken (a friction fit's ϑ stuck on
        its bound is the refinement's business)."""
        kept: list[Estimate] = []
        for e in new:
            if start or _identified(e):
                kept.append(e)
            else:
                self.problems.append(
                    f"{e.key}: the runs cannot identify it ({e.value:.4g} ± {e.std:.2g}); "
                    f"kept {self.params.number(e.key):.4g}, the value it had")
        self.estimates.extend(kept)
        self.params = self.params.replace({e.key: e.value for e in kept}, "identify")

    def forget(self, prefix: str) -> None:
        """Drop the estimates of the keys starting with ``prefix`` (a step redone)."""
        self.estimates[:] = [e for e in self.estimates if not e.key.startswith(prefix)]

    def step(self, name: str, runs: Sequence[ClassifiedRun], missing: str,
             action: Callable[[], None]) -> None:
        """Run one step on ``runs``; skipped (and said) without them, reported if it fails."""
        if not runs:
            self.problems.append(f"{name}: skipped, no {missing} run in the campaign")
            self.missed.append(name)
            return
        self.say(f"identifying {name}")
        try:
            action()
        except (IdentificationError, ParameterError, np.linalg.LinAlgError) as exc:
            self.problems.append(f"{name}: failed ({exc})")
            self.missed.append(name)


def identify(runs: Sequence[Run], base: RigParameters, fix_theta3: bool = False,
             progress: Progress | None = None, *, friction: bool = True,
             jackknife: bool = True) -> Identification:
    """Calibrate ``base`` on ``runs``; a step without usable runs is skipped and reported.

    ``friction=False`` keeps the friction curve of ``base`` (a model without a calibrated
    curve, for the diagnosis); ``jackknife=False`` skips the leave-one-run-out spread of
    the friction estimate (its σ is then the residual-based one, and identify is ~4x
    faster).
    """
    with single_threaded_blas():
        return _identify(runs, base, fix_theta3, progress, friction, jackknife)


def _identify(runs: Sequence[Run], base: RigParameters, fix_theta3: bool,
              progress: Progress | None, friction: bool, jackknife: bool) -> Identification:
    state = _Calibration(base, progress or (lambda _msg: None))
    classified, left_out = fully_logged(classify_all(runs), "the calibration")
    state.problems.extend(left_out)
    check_units(classified, base)
    state.problems.extend(unit_notes(classified, base))
    ramps = select(classified, [RunKind.ACTUATOR_RAMP])
    dynamic = select(classified, [RunKind.ACTUATOR_DYNAMIC])
    braking = select(classified, [Setup.BRAKE])

    def dynamics() -> None:
        found, state.frf, notes = fit_actuator_dynamics(dynamic, state.params)
        state.adopt(found)
        state.problems.extend(notes)

    if ramps or not dynamic:
        state.step("valve static map", ramps, "quasi-static ramp",
                   lambda: state.adopt(fit_static_map(ramps, state.params)))
    else:  # a step log: the map's gain from its held levels
        state.step("valve static map (held levels)", dynamic, "actuator",
                   lambda: state.adopt(fit_map_to_holds(dynamic, state.params)))
    state.step("actuator dynamics A(s)", dynamic, "actuator steps/sweep", dynamics)
    _braking_steps(state, braking, fix_theta3, friction, jackknife)
    return Identification(state.params, tuple(state.estimates),
                          {r.name: r.kind for r in classified}, tuple(state.problems), state.frf,
                          tuple(state.missed))


def _braking_steps(state: _Calibration, runs: Sequence[ClassifiedRun], fix_theta3: bool,
                   friction: bool, jackknife: bool) -> None:
    """Each its own step, so that a note names the one that failed; a step that fails
    leaves the base values to the steps after it."""
    prepared: list[br.Braking] = []
    state.step("braking runs (speeds, slip, forces)", runs, "braking",
               lambda: prepared.extend(br.prepare(r, state.params) for r in runs))
    if not prepared:
        return
    state.step("unloaded rolling radius", runs, "braking",
               lambda: state.adopt([br.fit_unloaded_radius(prepared, state.params)]))
    state.step("flywheel inertia and drag", runs, "braking",
               lambda: state.adopt(flywheel.fit_flywheel(prepared, state.params)))
    state.step("brake gain", runs, "braking",
               lambda: state.adopt(br.fit_brake_gain(prepared, state.params)))
    if friction:
        state.step("friction curve", runs, "braking",
                   lambda: _friction_step(state, runs, prepared, fix_theta3, jackknife))


def _refinement_start(direct: RigParameters, before: RigParameters) -> RigParameters:
    """``direct`` with each ϑ the direct fit drove onto its zero bound back at its value
    ``before``: the refinement scales its start, and 0 scaled stays 0 (stops that never
    left low slip once gave ϑ3 = 2.5e-10 ± 1e-24 where the rig had 0.145)."""
    stuck = {k: before.number(k) for k in FRICTION_KEYS
             if direct.number(k) < ZERO_BOUND_FRACTION * before.number(k)}
    return direct.replace(stuck, "refinement start") if stuck else direct


def _no_tyre_curve(params: RigParameters) -> str | None:
    """Why the friction curve of ``params`` is no tyre's (None when it may be one): slips
    misread by a model without the radius law, at two static loads, once gave ϑ = 823, 0.93,
    181, a near-straight line 35 times as stiff as a tyre, and every output-error step then
    simulated that much slower."""
    t1, t2, t3 = (params.number(k) for k in FRICTION_KEYS)
    if t1 > MAX_THETA1:
        return f"ϑ1 = {t1:.3g} > {MAX_THETA1:g}"
    if t1 * t2 + t3 > MAX_SLIP_STIFFNESS:
        return f"dμ/dλ at zero slip {t1 * t2 + t3:.3g} > {MAX_SLIP_STIFFNESS:g}"
    return None


def _friction_step(state: _Calibration, runs: Sequence[ClassifiedRun],
                   prepared: Sequence[br.Braking], fix_theta3: bool, jackknife: bool) -> None:
    before = state.params
    state.adopt(fit_friction(prepared, state.params, fix_theta3), start=not fix_theta3)
    if fix_theta3:
        return
    implausible = _no_tyre_curve(state.params)
    if implausible:  # the samples' slips are misread: keep the model's curve, the stops tell
        state.problems.append(f"friction curve: the direct fit is no tyre's curve "
                              f"({implausible}); the model's curve kept or refined")
        state.forget("friction.")
        state.params = state.params.replace({k: before.number(k) for k in FRICTION_KEYS},
                                            "the model's friction curve")
    state.say("refining the friction curve on the braking runs (output error)")
    refined = refine_friction(runs, _refinement_start(state.params, before), jackknife)
    state.forget("friction.")
    state.adopt(refined)
