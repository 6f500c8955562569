"""Candidate extensions fitted on campaigns that hide them (parameters unseen by the code)."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.runs import classify_all
from landing_gear_sim.diagnosis.catalogue import CATALOGUE, fit_candidate, gear_walk_key_parameters
from landing_gear_sim.diagnosis.local_gain import campaign_gain
from msg_tools.io import read_campaign

ACTUATOR_RUNS = ("actuator_ramp", "actuator_steps_sweep")
BRAKING_RUNS = ("brake_const_20bar", "brake_const_40bar", "brake_osc_low", "brake_osc_high")


def _hidden(reference, tmp_path, seed, effect, names):
    """Campaign of a rig off its datasheet, with ``effect(rng)`` switched on; and its truth."""
    rng = np.random.default_rng(seed)
    rig = rig_like(reference, rng)
    rig = rig.replace(effect(rng))
    generate_campaign(tmp_path, rig, seed, names)
    return read_campaign(tmp_path).runs, rig


@pytest.mark.parametrize("seed", [21, 22])
def test_actuator_delay_is_recovered_within_a_millisecond(reference, tmp_path, seed):
    runs, rig = _hidden(reference, tmp_path, seed, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": rng.uniform(0.002, 0.02)},
        ACTUATOR_RUNS)
    fit = fit_candidate(CATALOGUE["actuator_delay"], runs,
                        identify(runs, reference, jackknife=False).params)
    assert fit.values["actuator.delay_s"] == pytest.approx(rig.number("actuator.delay_s"),
                                                           abs=1e-3), seed
    assert fit.values["actuator.natural_frequency_hz"] == pytest.approx(
        rig.number("actuator.natural_frequency_hz"), rel=0.05)


def test_pressure_sensor_offset_is_recovered_within_20_percent(reference, tmp_path):
    runs, rig = _hidden(reference, tmp_path, 23, lambda rng: {
        "elements.pressure_sensor_offset": True,
        "sensors.pressure_offset_pa": rng.choice([-1, 1]) * rng.uniform(0.3e5, 1.5e5)},
        ACTUATOR_RUNS)
    fit = fit_candidate(CATALOGUE["pressure_sensor_offset"], runs,
                        identify(runs, reference, jackknife=False).params)
    assert fit.values["sensors.pressure_offset_pa"] == pytest.approx(
        rig.number("sensors.pressure_offset_pa"), rel=0.2)


def test_gear_walk_is_rediscovered_from_a_model_without_it(reference, tmp_path):
    """The paper's story: start from the single-corner model, find the ~8 Hz gear walk."""
    runs, rig = _hidden(reference, tmp_path, 25, lambda rng: {
        "gear_walk.stiffness_n_m_per_rad": 6.9e5 * rng.uniform(0.7, 1.4)},
        ACTUATOR_RUNS + BRAKING_RUNS)
    start = identify(runs, reference.without("gear_walk"), jackknife=False).params
    fit = fit_candidate(CATALOGUE["gear_walk"], runs, start, datasheet=reference)
    found, truth = gear_walk_key_parameters(fit.params), gear_walk_key_parameters(rig)
    assert found["frequency_hz"] == pytest.approx(truth["frequency_hz"], rel=0.05)


def test_the_right_candidate_explains_more_than_a_wrong_one(reference, tmp_path):
    runs, _ = _hidden(reference, tmp_path, 26, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": 0.008}, ACTUATOR_RUNS)
    calibrated = identify(runs, reference, jackknife=False).params
    right = fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated)
    wrong = fit_candidate(CATALOGUE["pressure_sensor_offset"], runs, calibrated)
    assert right.cost < 0.5 * wrong.cost


def test_a_fits_jacobian_is_scipys_forward_difference_within_its_bounds():
    """The fits' Jacobian simulates its columns side by side; it must be the one scipy's
    '2-point' differences gave (relative steps, backward at the box's edge), to the bit and
    in its layout: the solver's rounding follows it, and a 1-ulp step once moved a fade's
    fit to another optimum."""
    from scipy.optimize._numdiff import approx_derivative

    from landing_gear_sim.calibration.differences import DIFF_STEP, Objective

    matrix = np.random.default_rng(3).normal(size=(9, 4))
    calls: list[int] = []

    def values(u):
        return np.sin(matrix @ u) + np.sum(u) ** 2

    def residuals(points):
        calls.append(len(points))
        return [values(u) for u in points]

    objective = Objective(residuals)
    for u in (np.array([0.2, 0.5, 0.7, 0.9]), np.array([0.0, 1.0, 1e-6, 1.0 - 1e-6])):
        objective.fun(u)
        ours = objective.jac(u)
        theirs = approx_derivative(values, u, method="2-point", rel_step=DIFF_STEP,
                                   bounds=(0.0, 1.0))
        assert np.array_equal(ours, theirs)
        assert ours.flags.f_contiguous == theirs.flags.f_contiguous
    assert calls == [1, 4, 1, 4]  # the columns in one call; the point's residual reused
    # another box: the friction curve's refinement, in factors of its start
    within = Objective(residuals, 0.2, 5.0)
    for u in (np.array([0.2, 1.0, 4.9999, 5.0]), np.array([1.3, 0.2000001, 2.0, 4.0])):
        within.fun(u)
        theirs = approx_derivative(values, u, method="2-point", rel_step=DIFF_STEP,
                                   bounds=(0.2, 5.0))
        assert np.array_equal(within.jac(u), theirs)
    # where a fit before ended (a probe's optimum): its Jacobian given back, layout and all
    u = np.array([0.3, 0.1, 0.8, 0.6])
    known = Objective(residuals, known=(u, values(u), objective.jac(u)))
    calls.clear()
    again = known.jac(u.copy())
    assert calls == [] and np.array_equal(again, objective.jac(u))
    assert again.flags.f_contiguous


def _valley(structure: np.ndarray):
    """Residuals of a curved valley (Rosenbrock's, on the unit box) beside ``structure``,
    which no parameter explains: a fit that crawls along the valley."""
    def residuals(points):
        return [np.concatenate([structure, [10.0 * (u[1] - u[0] ** 2), 1.0 - u[0]]])
                for u in points]
    return residuals


def _fit(residuals, negligible_score=None):
    """The fits' own optimiser on ``residuals``; with ``negligible_score=0``, stopping at
    FTOL alone."""
    from landing_gear_sim.calibration import statistics
    from landing_gear_sim.calibration.differences import Objective
    from landing_gear_sim.diagnosis import catalogue

    with pytest.MonkeyPatch.context() as patch:
        if negligible_score is not None:
            patch.setattr(statistics, "NEGLIGIBLE_SCORE", negligible_score)
        return catalogue._optimise(Objective(residuals), np.array([0.05, 0.9]),
                                   catalogue.MAX_ITERATIONS)


def test_a_fit_whose_residual_is_structure_stops_when_its_steps_no_longer_move_the_score():
    """Where the residual is mostly what no parameter explains (few effective samples: a
    fade fitted before the valve's delay is in), steps worth less than a tenth in
    n_eff·ln(RSS), the unit of ΔBIC and the held-out score, decide nothing: the fit stops
    there, not at a relative 1e-5 of its cost (it had crawled 18 of 34 steps for 0.3 %)."""
    from landing_gear_sim.calibration.statistics import effective_count

    structure = np.sin(np.linspace(0.0, 3.0, 2000))  # smooth: n_eff ~ 360 of 2002
    residuals = _valley(structure)
    ours, crawl = _fit(residuals), _fit(residuals, 0.0)
    n_eff = effective_count(residuals([crawl.x])[0])
    assert ours.nfev < crawl.nfev
    assert n_eff * np.log(ours.cost / crawl.cost) < 0.5  # what it left lies under any threshold
    # a residual at the noise (every sample its own information) is fitted as before
    noise = np.random.default_rng(5).normal(size=20000)
    white, plain = _fit(_valley(noise)), _fit(_valley(noise), 0.0)
    assert white.nfev == plain.nfev and np.array_equal(white.x, plain.x)


def test_candidates_that_refit_the_same_base_parameters_share_one_null_fit(reference,
                                                                          tmp_path,
                                                                          monkeypatch):
    """A family's proposals differ in their terms' codes, not in their null (those terms at
    0): each had fitted the same null again."""
    from dataclasses import replace

    from landing_gear_sim.diagnosis import scoring
    from landing_gear_sim.diagnosis.catalogue import CandidateFit
    from landing_gear_sim.model import keys as K

    runs, _ = _hidden(reference, tmp_path, 31, lambda rng: {}, ("brake_const_20bar",))
    fits: list[str] = []

    def fit(candidate, runs, model, *args, **kwargs):
        fits.append(candidate.cause)
        return CandidateFit(candidate, model, {}, {}, np.zeros(1))

    monkeypatch.setattr(scoring, "fit_candidate", fit)
    candidate = replace(CATALOGUE["tire_relaxation"], keys=())
    code, coefficient = K.WHEEL_TERMS[0]
    scales = {(r.name, c): 1.0 for r in runs for c in candidate.channels}
    for value in (17.0, 33.0):
        null = scoring._null_fit(candidate, runs, reference.replace({code: value}), reference,
                                 scales)
        assert null.params.number(code) == value  # the model's own codes, not the first's
    assert fits == ["tire_relaxation"]
    acting = reference.replace({code: 17.0, coefficient: 3.0})
    scoring._null_fit(candidate, runs, acting, reference, scales)
    assert len(fits) == 2
    fitting_it = replace(candidate, free=(*candidate.free, coefficient))  # its code matters
    for value in (17.0, 33.0):
        scoring._null_fit(fitting_it, runs, reference.replace({code: value}), reference,
                          scales)
    assert len(fits) == 4


def test_a_pool_task_takes_the_cores_the_pools_other_tasks_leave(monkeypatch):
    """The diagnosis scores its candidates in a process per core; its longest fit had run
    on one core while the other idled once the rest were scored."""
    from landing_gear_sim import processes

    monkeypatch.setattr(processes.os, "cpu_count", lambda: 2)
    monkeypatch.setattr(processes, "_BUSY", processes.busy_counter())
    with processes.working():
        with processes.working():  # another task at work: a core each
            assert processes.threads() == 1
        assert processes.threads() == 2  # alone
    monkeypatch.setattr(processes, "_BUSY", None)
    monkeypatch.setattr(processes, "_THREADS", 1)
    assert processes.threads() == 1  # a worker of a pool that shares no count


def _counting(monkeypatch) -> list[tuple[str, bytes]]:
    """The parameter sets the candidate fits simulate, in order, as bytes, each with how:
    "plain", or "dual" (its residual and its derivatives, in one pass)."""
    from landing_gear_sim.diagnosis import catalogue

    simulated: list[tuple[str, bytes]] = []
    original = catalogue.scaled_residuals
    with_derivatives = catalogue.scaled_residuals_and_jacobian

    def counted(runs, trials, *args, **kwargs):
        simulated.extend(("plain", t.vector().tobytes()) for t in trials)
        return original(runs, trials, *args, **kwargs)

    def counted_with_derivatives(runs, trial, *args, **kwargs):
        simulated.append(("dual", trial.vector().tobytes()))
        return with_derivatives(runs, trial, *args, **kwargs)

    monkeypatch.setattr(catalogue, "scaled_residuals", counted)
    monkeypatch.setattr(catalogue, "scaled_residuals_and_jacobian", counted_with_derivatives)
    return simulated


def test_a_fit_simulates_its_start_once(reference, tmp_path, monkeypatch):
    """The starts are simulated to rank them; the optimiser then asked for the chosen one's
    residual again (and the final fit for the best probe's), a campaign simulation each for
    nothing. A set is simulated plainly at most once, and with its derivatives (the dual
    pass the plain one cannot stand for) at most once."""
    runs, _ = _hidden(reference, tmp_path, 26, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": 0.008}, ACTUATOR_RUNS)
    calibrated = identify(runs, reference, jackknife=False).params
    simulated = _counting(monkeypatch)
    fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated)
    assert len(set(simulated)) == len(simulated) > 8


def test_a_start_both_references_give_is_simulated_and_probed_once(reference, tmp_path,
                                                                   monkeypatch):
    """A fit starts from the calibrated model and from the datasheet. Where the two agree on
    the free parameters they give one start twice: it was ranked twice and probed twice, a
    quarter of a discovered term's simulations (issue 61: nothing computed twice)."""
    runs, _ = _hidden(reference, tmp_path, 26, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": 0.008}, ACTUATOR_RUNS)
    calibrated = identify(runs, reference, jackknife=False).params
    simulated = _counting(monkeypatch)
    fit = fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated, datasheet=calibrated)
    assert len(set(simulated)) == len(simulated) > 8
    assert fit.values["actuator.delay_s"] == pytest.approx(0.008, abs=1e-3)


def test_a_candidate_tried_again_starts_where_it_ended(reference, tmp_path, monkeypatch):
    """A candidate a round leaves for the next (it helped, another helped more) was fitted
    from its catalogue starts again: I02's fade took 20 evaluations and 15 Jacobians in
    round 2 after 18 and 16 in round 1. Given where it ended, it reaches the same optimum in
    fewer simulations."""
    runs, _ = _hidden(reference, tmp_path, 26, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": 0.008}, ACTUATOR_RUNS)
    calibrated = identify(runs, reference, jackknife=False).params
    simulated = _counting(monkeypatch)
    first = fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated)
    cold = len(simulated)
    again = fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated, ended=first.values)
    assert len(simulated) - cold < cold
    assert again.values["actuator.delay_s"] == pytest.approx(first.values["actuator.delay_s"],
                                                             abs=1e-4)
    assert again.cost <= first.cost * (1 + 1e-3)


def test_a_fit_that_stops_on_its_budget_says_so_in_the_candidates_reason(
        reference, tmp_path, monkeypatch):
    """Issue 61: a fit that ran out of evaluations ends where it stood, which need not be its
    optimum; its candidate's reason says so."""
    from landing_gear_sim.diagnosis import catalogue, scoring

    runs, _ = _hidden(reference, tmp_path, 26, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": 0.008}, ACTUATOR_RUNS)
    calibrated = identify(runs, reference, jackknife=False).params
    assert not fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated).stopped
    monkeypatch.setattr(catalogue, "MAX_ITERATIONS", 2)
    stopped = fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated)
    assert stopped.stopped
    reason = scoring._reason("", stopped)
    assert reason.startswith(scoring.ACCEPTED) and "budget of 2 evaluations" in reason


def test_a_fade_is_fitted_only_where_the_brake_gain_falls_with_the_energy_absorbed(
        reference, tmp_path):
    """Issue 61: the fade's fit and its null took 42 % of the fits' time of diagnoses that
    had no fade to find. A fade lowers the brake gain as the brake absorbs energy; a small
    one (drawn here) is fitted, and a rig without one says why it is not."""
    from landing_gear_sim.model import keys as K

    names = ACTUATOR_RUNS[:1] + BRAKING_RUNS
    fraction = float(np.random.default_rng(612).uniform(0.02, 0.05))
    reasons, falls = {}, {}
    for name, effect in (("none", lambda rng: {}), ("fade", lambda rng: {
            "elements.brake_fade": True, K.BRAKE_FADE_FRACTION: fraction,
            K.BRAKE_FADE_ENERGY_J: rng.uniform(1e6, 5e6)})):
        runs = classify_all(_hidden(reference, tmp_path / name, 612, effect, names)[0])
        calibrated = identify(runs, reference, jackknife=False).params
        reasons[name] = CATALOGUE["brake_fade"].evidence(runs, calibrated)
        falls[name] = campaign_gain(runs, calibrated, "brake energy").change
    assert reasons["fade"] == "", reasons["fade"]
    assert reasons["none"].startswith("the brake gain does not fall with the energy"), reasons
    # what the fade leaves of itself after the calibration (it takes about half)
    assert -fraction < falls["fade"] < -0.2 * fraction, (falls, fraction)


def test_a_relaxation_is_fitted_only_where_the_tyres_force_lags_its_curve(reference,
                                                                         tmp_path):
    """Issue 61: the relaxation's fit and its null took 27 % of the fits' time of diagnoses
    that had no relaxation to find. A relaxing tyre's force lags its curve by σ/v: a length
    drawn here is read back from the tyre's error, and a rig without one says why it is not
    fitted."""
    from landing_gear_sim.diagnosis.equations.tyre import relaxation_read
    from landing_gear_sim.model import keys as K

    names = ACTUATOR_RUNS[:1] + BRAKING_RUNS
    length = float(np.random.default_rng(613).uniform(0.05, 0.3))
    reasons, read = {}, {}
    for name, effect in (("none", lambda rng: {}), ("relaxing", lambda rng: {
            "elements.tire_relaxation": True, K.TYRE_RELAXATION_LENGTH_M: length})):
        runs = classify_all(_hidden(reference, tmp_path / name, 613, effect, names)[0])
        calibrated = identify(runs, reference, jackknife=False).params
        reasons[name] = CATALOGUE["tire_relaxation"].evidence(runs, calibrated)
        read[name] = relaxation_read(runs, calibrated)
    assert reasons["relaxing"] == "", reasons["relaxing"]
    assert reasons["none"].startswith("the tyre's force does not lag its curve"), reasons
    assert read["relaxing"][0] == pytest.approx(length, rel=0.2)
    # where the force hardly moves (stops at constant pressure alone) the samples cannot
    # read the length: not reading one there rules nothing out, and it is fitted
    steady = classify_all(_hidden(reference, tmp_path / "steady", 613, lambda rng: {},
                                  ("actuator_ramp", "brake_const_20bar", "brake_const_40bar"))[0])
    calibrated = identify(steady, reference, jackknife=False).params
    assert CATALOGUE["tire_relaxation"].evidence(steady, calibrated) == ""
