"""Never `none` while the data disagree (issue 64, item 1): a channel the model misses by
more than its logger's noise is an `unexplained` finding in its equation, said where in time
it misses; a channel within its noise is not. On one run, in milliseconds."""

from __future__ import annotations

import dataclasses
import re
from types import SimpleNamespace

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import NOISE
from landing_gear_sim.calibration.runs import classified
from landing_gear_sim.diagnosis import diagnose as dg
from landing_gear_sim.diagnosis.misfit import MISFIT_MULTIPLE, misfits
from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate


@pytest.fixture(scope="module")
def stop(reference):
    """A 30 bar stop as logged (the generator's noise) and as the model simulates it."""
    rig = reference.replace(NOISE, "a logger's noise")
    result = simulate(rig, sc.constant_pressure_test(rig, 30e5))
    return classified(result.to_run(noise=3)), result.to_run()


SPAN_S = (3.0, 9.0)  # the logged pressure reads off the model's: held, in a 14.7 s stop


def _bumped(run, size_pa: float):
    """``run`` with its pressure ``size_pa`` higher over SPAN_S (a whole-run RMSE measures
    a misfit: a 0.4 s one in this stop reads 1.5 times the noise)."""
    t = run.time_s - run.time_s[0]
    bump = np.where((t >= SPAN_S[0]) & (t < SPAN_S[1]), size_pa, 0.0)
    return dataclasses.replace(run, pressure_pa=run.pressure_pa + bump)


def test_a_run_within_its_loggers_noise_is_no_misfit(stop):
    measured, model = stop
    assert misfits([measured], [model]) == []


def test_a_pressure_missed_beyond_its_noise_is_found_in_the_valve_where_it_misses(stop):
    measured, model = stop
    size = float(np.random.default_rng(64).uniform(1.2e5, 2.0e5))  # drawn: 1.2-2 bar
    [found] = misfits([_bumped(measured, size)], [model])
    noise = NOISE[K.SENSORS_PRESSURE_NOISE_PA]
    t = measured.time_s - measured.time_s[0]
    share = np.mean((t >= SPAN_S[0]) & (t < SPAN_S[1]))
    assert found.channel == "pressure_pa" and found.multiple > MISFIT_MULTIPLE
    assert found.rmse == pytest.approx(np.sqrt(share * size ** 2 + noise ** 2), rel=0.05)
    assert found.noise == pytest.approx(noise, rel=0.2)
    assert abs(found.start_s - SPAN_S[0]) < 0.2 and abs(found.end_s - SPAN_S[1]) < 0.2, found


def test_a_misfit_beside_no_accepted_cause_is_unexplained_not_none(stop):
    """The measured failure: the starting model fitted the pressure at 87 % where nulls
    fit 97-99 %, no relation was violated, no candidate accepted, and the verdict was
    `none`."""
    measured, model = stop
    start = SimpleNamespace(runs=[_bumped(measured, 1.5e5)], problems=[], skipped=[])
    verdict, [finding] = dg._verdict(start, [], [], None, [], [model], [])
    assert verdict == "unexplained" and finding.equation == "valve"
    assert finding.channel == "pressure_pa" and finding.parameters["rmse_over_noise"] > 4
    assert re.search(r"misses the brake pressure by [\d.]+ times its logger's noise on "
                     r"brake_const_30bar .* where the brake pressure holds \(31", finding.evidence)
    quiet = SimpleNamespace(runs=[measured], problems=[], skipped=[])
    assert dg._verdict(quiet, [], [], None, [], [model], []) == ("none", [])


def test_one_run_of_three_missed_is_that_runs_moment_two_are_a_missing_law(stop):
    """An own null at 200 Hz through a noisy ADC read its wheel speed 4.2 times its noise on
    one stop of six (a lock-up's moment) and became `unexplained`: a model that lacks a law
    misses it run after run."""
    measured, model = stop
    missed = _bumped(measured, 1.5e5)
    runs = [dataclasses.replace(r, name=f"stop_{i}") for i, r in
            enumerate((missed, measured, measured))]
    assert misfits(runs, [model] * 3) == []
    runs[1] = dataclasses.replace(missed, name="stop_1")
    assert [m.run for m in misfits(runs, [model] * 3)] == ["stop_0", "stop_1"]


def test_a_discovered_law_its_equation_still_misses_reads_approximately(reference, tmp_path):
    """Issue 64, item 5: a grip changing sharply near standstill read as sgn ω plus √v, with an
    `unexplained` left in the same equation, and the law was stated as if exact."""
    from landing_gear_sim.diagnosis.diagnose import Diagnosis
    from landing_gear_sim.diagnosis.families import EQUATIONS
    from landing_gear_sim.diagnosis.findings import Finding, approximations
    from landing_gear_sim.report.words import headline

    def finding(cause: str, family: str = "", equation: str = "") -> Finding:
        return Finding(cause=cause, parameters={}, std={}, evidence="", fit_before={},
                       fit_after={}, delta_bic=None, held_out=None, accepted=True,
                       family=family, term="μ = μ_B(λ) + 0.02·sgn ω" if family else "",
                       equation=equation)

    tyre, wheel = finding("discovered", "tyre"), finding("discovered", "wheel")
    left = finding("unexplained", equation="tyre")
    marked = approximations([tyre, wheel, left], EQUATIONS)
    assert [f.approximate for f in marked] == [True, False, False]
    assert not approximations([tyre], EQUATIONS)[0].approximate
    assert marked[0].to_json()["approximate"] is True and "approximate" not in wheel.to_json()
    result = Diagnosis(verdict="discovered", findings=marked, candidates=[], baseline={},
                       start=reference, calibrated=reference, extended=reference,
                       signatures_before=[], signatures_after=[])
    assert "approximately μ = μ_B(λ) + 0.02·sgn ω" in headline(result)
