"""Identification and validation on a campaign generated with parameters the code never sees."""

from __future__ import annotations

import dataclasses
import json
import re
import shutil

import numpy as np
import pytest

from landing_gear_sim.calibration import friction, statistics
from landing_gear_sim.calibration import runs as runs_module
from landing_gear_sim.calibration.braking import prepare
from landing_gear_sim.calibration.campaign import (
    DEVIATING,
    LIGHT_BAR,
    LIGHT_LOAD,
    NOISE,
    generate_campaign,
    rig_like,
)
from landing_gear_sim.calibration.friction import fit_friction
from landing_gear_sim.calibration.identify import MAX_SLIP_STIFFNESS, MAX_THETA1, identify
from landing_gear_sim.calibration.measured import CHANNELS, run_static_load_n, simulate_run
from landing_gear_sim.calibration.plausibility import unit_notes
from landing_gear_sim.calibration.runs import (
    RunKind,
    Setup,
    classified,
    classify,
    classify_all,
    select,
)
from landing_gear_sim.calibration.validate import channel_verdicts, fit_percent, validate
from landing_gear_sim.cli import main
from landing_gear_sim.diagnosis.start import starting_model
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.model.scenario import constant_pressure_test
from landing_gear_sim.report.validation_tables import validation_sentence
from msg_tools.csv_io import write_csv
from msg_tools.io import read_campaign
from msg_tools.units import PA_PER_BAR

# the campaign and its identification are fixtures: on one worker, computed once
pytestmark = pytest.mark.xdist_group("identified_campaign")

SEED = 11  # the hidden rig: datasheet values off by up to ±3 %, never shown to identify()


@pytest.fixture(scope="module")
def hidden_rig(reference):
    return rig_like(reference, np.random.default_rng(SEED), deviation=0.03)


@pytest.fixture(scope="module")
def campaign_dir(tmp_path_factory, hidden_rig):
    folder = tmp_path_factory.mktemp("campaign")
    generate_campaign(folder, hidden_rig, SEED)
    (folder / "generating-parameters.yaml").rename(folder.parent / f"hidden-{SEED}.yaml")
    return folder


@pytest.fixture(scope="module")
def identified(campaign_dir, reference):
    return identify(read_campaign(campaign_dir).runs, reference)


def test_runs_are_classified_from_their_signals(identified):
    assert identified.classes == {
        "actuator_ramp": "actuator_ramp", "actuator_steps_sweep": "actuator_dynamic",
        **{f"brake_const_{b}bar": "brake_constant" for b in (10, 20, 30, 40)},
        "brake_osc_high": "brake_oscillating", "brake_osc_low": "brake_oscillating"}


def test_identification_recovers_the_hidden_rig(identified, hidden_rig):
    found = {e.key: e for e in identified.estimates}
    for key in DEVIATING:
        estimate = found[key]
        assert estimate.value == pytest.approx(hidden_rig.number(key), rel=0.05), (SEED, key)
        assert 0 < estimate.std < abs(estimate.value) and estimate.runs
        # the stated uncertainty is honest: the truth lies within 4 σ
        assert abs(estimate.value - hidden_rig.number(key)) < 4 * estimate.std + 1e-3 * abs(
            estimate.value), (key, estimate)
    for key in ("actuator.natural_frequency_hz", "actuator.damping_ratio",
                "brake.gain_n_m_per_pa", "friction.theta1"):
        assert found[key].value == pytest.approx(hidden_rig.number(key), rel=0.01), (SEED, key)


def test_calibrated_model_fits_the_oscillating_runs(identified, campaign_dir):
    for comparison in validate(read_campaign(campaign_dir).runs, identified.params):
        if comparison.kind == "brake_oscillating":
            assert comparison.scores["wheel_speed_rad_s"].fit_percent >= 95.0
            assert comparison.scores["pressure_pa"].fit_percent >= 95.0


def test_datasheet_model_fits_worse_than_the_calibrated_one(identified, campaign_dir, reference):
    runs = [r for r in read_campaign(campaign_dir).runs if r.name == "brake_osc_low"]
    before = validate(runs, reference)[0].scores["wheel_speed_rad_s"].fit_percent
    after = validate(runs, identified.params)[0].scores["wheel_speed_rad_s"].fit_percent
    assert after > before


def test_steps_without_their_runs_are_skipped_and_the_rest_runs(campaign_dir, reference,
                                                                 tmp_path):
    for run in campaign_dir.glob("brake_*.csv"):
        shutil.copy(run, tmp_path / run.name)
    # the steps that run and those skipped, not their spread: no leave-one-run-out fits
    result = identify(read_campaign(tmp_path).runs, reference, jackknife=False)
    assert any("valve static map: skipped" in p for p in result.problems)
    assert any("actuator dynamics A(s): skipped" in p for p in result.problems)
    assert {e.key for e in result.estimates} >= {"friction.theta1", "brake.gain_n_m_per_pa"}


def test_fixing_theta3_keeps_it(identified, campaign_dir, reference):
    result = identify(read_campaign(campaign_dir).runs, reference, fix_theta3=True)
    assert result.params.number("friction.theta3") == reference.number("friction.theta3")


def test_identify_cli_writes_params_and_evidence(campaign_dir, tmp_path, capsys, hidden_rig):
    out = tmp_path / "calibrated.yaml"
    assert main(["identify", str(campaign_dir), "-o", str(out)]) == 0
    params = load_parameters([out])
    assert params.number("brake.gain_n_m_per_pa") == pytest.approx(
        hidden_rig.number("brake.gain_n_m_per_pa"), rel=0.01)
    evidence = json.loads(out.with_suffix(".identification.json").read_text())
    assert {e["key"] for e in evidence["estimates"]} >= set(DEVIATING)
    assert main(["validate", str(campaign_dir), "--config", str(out),
                 "--report", str(tmp_path / "report")]) == 0
    page = (tmp_path / "report" / "index.html").read_text()
    assert "brake_osc_low.png" in page and "friction.png" in page
    assert "actuator_steps_sweep_frf.png" in page  # the actuator's FRF against the model's
    assert (tmp_path / "report" / "actuator_steps_sweep_frf.png").stat().st_size > 10_000
    assert "fit % = 100·(1 − ‖y − ŷ‖" in page  # issue 32: the fit defined, RMSE, max error
    # issue 63: a verdict, first, and on the terminal: pass or fail per channel
    verdict = page.split(">Verdict</h2>")[1].split("<h2")[0]
    assert "<b>Pass: the model matches the rig within 3 times" in verdict
    assert verdict.count("<td>pass</td>") == 5 and page.index("Verdict") < page.index("Model")
    assert "Pass: the model matches" in capsys.readouterr().out
    errors = page.split("RMSE / max |error| per run and channel</h2>")[1]
    assert "pressure [bar]" in errors and re.search(r"<td>\d[\d.e-]* / \d[\d.e-]*</td>", errors)
    capsys.readouterr()


def test_failed_identify_overwrites_nothing(tmp_path, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "broken.csv").write_text("time_s,foo\n0,1\n")
    out = tmp_path / "calibrated.yaml"
    out.write_text("keep me\n")
    assert main(["identify", str(empty), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "no readable run" in err and "broken.csv" in err
    assert out.read_text() == "keep me\n"


def test_classify_tells_actuator_only_from_braking(campaign_dir):
    runs = {r.name: r for r in read_campaign(campaign_dir).runs}
    assert classify(runs["actuator_ramp"]).startswith("actuator")
    assert classify(runs["brake_const_30bar"]) is RunKind.BRAKE_CONSTANT


def test_generated_campaign_is_reproducible(tmp_path, reference):
    rig = rig_like(reference, np.random.default_rng(1))
    a, b = tmp_path / "a", tmp_path / "b"
    generate_campaign(a, rig, 1)
    generate_campaign(b, rig, 1)
    assert (a / "brake_osc_low.csv").read_text() == (b / "brake_osc_low.csv").read_text()


def test_campaign_cli_refuses_to_overwrite(tmp_path, capsys):
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "run.csv").write_text("x\n")
    assert main(["campaign", str(tmp_path / "old")]) == 2
    assert "not empty" in capsys.readouterr().err
    assert main(["campaign", str(tmp_path / "new"), "--seed", "3"]) == 0
    assert len(list((tmp_path / "new").glob("*.csv"))) == 8
    assert main(["campaign", str(tmp_path / "light"), "--light-runs"]) == 0
    assert len(list((tmp_path / "light").glob("*_light.csv"))) == len(LIGHT_BAR)


def test_a_model_that_stops_early_still_follows_the_valve_pressure(campaign_dir, reference):
    """The valve does not depend on the wheel: after the model's stop its pressure goes on
    following the measured current (holding it made a stronger brake look like a worse
    actuator)."""
    run = next(r for r in read_campaign(campaign_dir).runs if r.name == "brake_osc_low")
    strong = reference.replace({"brake.gain_n_m_per_pa": 1.5 * reference.number(
        "brake.gain_n_m_per_pa")}, "test")
    simulated, result = simulate_run(run, strong)
    stopped = len(result)
    assert stopped < len(run) - 500
    assert np.array_equal(simulated.pressure_pa[:stopped], result.pressure_pa)
    assert np.ptp(simulated.pressure_pa[stopped:]) > 5e5  # still oscillating
    held = simulated.wheel_speed_rad_s[stopped:]
    assert np.all(held == held[0])
    tail = slice(stopped, None)
    assert fit_percent(run.pressure_pa[tail], simulated.pressure_pa[tail]) > 90.0


def test_identify_classifies_each_run_once(campaign_dir, reference, monkeypatch):
    """The kind travels with the run: the output-error fits (hundreds of simulations) never
    classify again."""
    calls = []
    real = runs_module.classify
    monkeypatch.setattr(runs_module, "classify",
                        lambda run, *rest: calls.append(run.name) or real(run, *rest))
    runs = read_campaign(campaign_dir).runs
    identify(runs, reference, jackknife=False)
    assert sorted(calls) == sorted(r.name for r in runs)


def test_simulating_a_measured_run_never_adds_noise(campaign_dir, reference):
    """A params file that carries sensor noise (a generator's) still compares noise-free."""
    run = next(r for r in read_campaign(campaign_dir).runs if r.name == "brake_const_30bar")
    noisy = reference.replace({"sensors.pressure_noise_pa": 2e4,
                               "sensors.speed_noise_rad_s": 0.1}, "test")
    first, second = simulate_run(run, noisy)[0], simulate_run(run, noisy)[0]
    clean = simulate_run(run, reference)[0]
    assert np.array_equal(first.pressure_pa, second.pressure_pa)
    assert np.array_equal(first.wheel_speed_rad_s, clean.wheel_speed_rad_s)


def test_a_run_at_another_static_load_is_simulated_at_its_own(tmp_path, identified,
                                                              hidden_rig):
    """The generator's light stops run at a lighter static load; a simulation of a measured
    run takes the run's own load from its free rolling (like its initial speed), so the
    vertical load channel is followed there as on every other stop."""
    light = f"brake_const_{LIGHT_BAR[0]}bar_light"
    generate_campaign(tmp_path, hidden_rig, SEED, ["brake_const_20bar", light], light=True)
    runs = {r.name: r for r in read_campaign(tmp_path).runs}
    full = hidden_rig.number("loading.static_load_n")
    for name, share in (("brake_const_20bar", 1.0), (light, LIGHT_LOAD)):
        run = classified(runs[name])
        assert run_static_load_n(run, identified.params) == pytest.approx(share * full,
                                                                          rel=2e-3)
        simulated = simulate_run(run, identified.params)[0]
        # at the model's static load the light stop's fit is negative
        assert fit_percent(run.vertical_load_n, simulated.vertical_load_n) > 95.0, name


COMPARED = ("actuator.map_k1_pa_per_a", "actuator.natural_frequency_hz",
            "actuator.damping_ratio", "brake.gain_n_m_per_pa", "flywheel.inertia_kg_m2",
            "wheel.unloaded_radius_m", "friction.theta1", "friction.theta2", "friction.theta3")


def test_jittered_timestamps_are_taken_off_and_every_parameter_stays(campaign_dir, identified,
                                                                    reference):
    """±10 % timestamp jitter once failed the braking step ("Time steps are not equally
    spaced") and still wrote a file; resampling it instead moved ω_n by 3 %. The stamps
    scatter around the logger's fixed-rate clock: its instants are used, no sample moved."""
    rng = np.random.default_rng(5)
    runs = [dataclasses.replace(r, time_s=r.time_s + rng.uniform(-0.1, 0.1, len(r)) / r.rate_hz)
            for r in read_campaign(campaign_dir).runs]
    jittered = identify(runs, reference, jackknife=False)
    assert jittered.problems == ()
    clean = {e.key: e for e in identified.estimates}
    for key in COMPARED:
        assert jittered.params.number(key) == pytest.approx(clean[key].value, rel=0.02), key


def test_short_gaps_are_bridged_and_long_ones_split_the_run(campaign_dir, tmp_path, identified,
                                                           reference):
    """A logger that dropped 3 samples here and there, and one that lost 0.3 s of the ramp
    and 0.2 s in the middle of a stop: every parameter as from the complete logs."""
    folder = tmp_path / "gappy"
    folder.mkdir()
    drops = {"actuator_steps_sweep": [slice(5000, 5003), slice(9000, 9002)],
             "actuator_ramp": [slice(4000, 4300)], "brake_const_30bar": [slice(3000, 3200)]}
    for source in campaign_dir.glob("*.csv"):
        lines = source.read_text().splitlines()
        rows = np.ones(len(lines), dtype=bool)
        for cut in drops.get(source.stem, []):
            rows[cut] = False
        (folder / source.name).write_text("\n".join(np.asarray(lines)[rows]) + "\n")
    campaign = read_campaign(folder)
    names = sorted(r.name for r in campaign.runs)
    assert "actuator_ramp__part1" in names and "actuator_ramp__part2" in names
    assert "brake_const_30bar__part1" in names and "brake_const_30bar__part2" not in names
    notes = "\n".join(campaign.problems)
    assert "actuator_steps_sweep: 2 short gap(s)" in notes
    assert "brake_const_30bar__part2: left out (it begins mid-stop" in notes
    gappy = identify(campaign.runs, reference, jackknife=False)
    assert gappy.complete, gappy.problems
    _assert_as_clean(gappy, identified)


def test_one_long_stop_does_not_decide_the_calibration(campaign_dir, tmp_path, identified,
                                                      hidden_rig, reference):
    """A 5-minute low-pressure stop beside the 10-60 s runs once dragged ϑ3 off by 9 %
    (the direct slip/μ fit, ruled by its 30 000 samples, put the refinement's start so far
    off that it ended on its bound). Each run now counts at most as a median-length one."""
    folder = tmp_path / "with_long_stop"
    shutil.copytree(campaign_dir, folder)
    rig = hidden_rig.replace({"rig_test.max_duration_s": 400.0}, "a long test")
    long_stop = simulate(rig, constant_pressure_test(rig, 0.8 * PA_PER_BAR)).to_run(noise=7)
    assert long_stop.time_s[-1] > 280
    write_csv(long_stop, folder / "brake_const_long.csv")
    direct = {name: _direct_friction_fit(path, reference)
              for name, path in (("without", campaign_dir), ("with", folder))}
    assert direct["with"] == pytest.approx(direct["without"], rel=0.25)  # was 4x on ϑ3
    result = identify(read_campaign(folder).runs, reference, jackknife=False)
    assert result.complete, result.problems
    _assert_as_clean(result, identified)


def _assert_as_clean(result, identified):
    """Every compared parameter within 2 % or 2 σ of the clean campaign's (issue 13)."""
    clean = {e.key: e for e in identified.estimates}
    for key in COMPARED:
        value, reference_value = result.params.number(key), clean[key].value
        assert abs(value - reference_value) <= max(0.02 * abs(reference_value),
                                                   2 * clean[key].std), key


def _direct_friction_fit(folder, params):
    """ϑ1..ϑ3 of the direct slip/μ fit (the refinement's start) on a folder's braking runs."""
    runs = select(classify_all(read_campaign(folder).runs), [Setup.BRAKE])
    return [e.value for e in fit_friction([prepare(r, params) for r in runs], params)]


@pytest.mark.parametrize("noise_a", [1e-3, 2e-3, 1e-2])
def test_current_logging_noise_changes_neither_classes_nor_parameters(campaign_dir, identified,
                                                                      reference, noise_a):
    """1 mA of noise on the logged current once made the ramp 'dynamic' (static map
    skipped) and, at 5 mA, every braking run 'oscillating'; exit 0 all the same.

    At 10 mA ϑ3 moves by up to 15 % (seeds 1-3: +2.5, −15, +7.4 %): the model's wheel-lock
    episodes respond to the noise left in the denoised command. Its σ says so (the
    leave-one-run-out spread: 3-43 %), so the estimate stays honest."""
    rng = np.random.default_rng(2)
    runs = [dataclasses.replace(r, current_a=r.current_a + rng.normal(0, noise_a, len(r)))
            for r in read_campaign(campaign_dir).runs]
    noisy = identify(runs, reference, jackknife=noise_a >= 5e-3)
    assert noisy.classes == identified.classes
    assert noisy.complete, noisy.problems
    clean = {e.key: e for e in identified.estimates}
    own = {e.key: e for e in noisy.estimates}
    for key in COMPARED:
        value, reference_value = noisy.params.number(key), clean[key].value
        sigma = max(clean[key].std, own[key].std)
        assert abs(value - reference_value) <= max(0.02 * abs(reference_value), 2 * sigma), key


def _rewritten(campaign_dir, folder, run_name, columns, factor):
    """The campaign with the comma-separated ``columns`` of one run multiplied by
    ``factor``."""
    folder.mkdir()
    for source in campaign_dir.glob("*.csv"):
        lines = source.read_text().splitlines()
        if source.stem == run_name:
            ks = [lines[0].split(",").index(c) for c in columns.split(",")]
            lines = lines[:1] + [",".join(
                f"{float(v) * factor:.12g}" if i in ks else v
                for i, v in enumerate(line.split(","))) for line in lines[1:]]
        (folder / source.name).write_text("\n".join(lines) + "\n")
    return folder


@pytest.mark.parametrize(("run_name", "columns", "factor", "fragments"), [
    ("brake_const_20bar", "brake_pressure_bar", 1e5 / 6894.757293168361,
     ["brake_pressure_bar is 14", "times what the valve map gives", "it looks like psi"]),
    ("brake_const_30bar", "wheel_speed_rad_s", 60 / (2 * np.pi),
     ["wheel_speed_rad_s is 9.", "while rolling freely", "it looks like rpm"]),
    ("brake_osc_low", "flywheel_speed_rad_s", 60 / (2 * np.pi),
     ["flywheel_speed_rad_s is 9.", "it looks like rpm"]),
    # both speeds alike roll together; the flywheel's momentum against the load cell's
    # force tells (was: identified, flywheel inertia -89.5 %, no problem noted)
    ("brake_const_30bar", "wheel_speed_rad_s,flywheel_speed_rad_s", 60 / (2 * np.pi),
     ["flywheel_speed_rad_s is 9.", "the load cell's force", "it looks like rpm",
      "wheel_speed_rad_s too"]),
    ("brake_const_20bar", "longitudinal_force_N", 1e-3,
     ["longitudinal_force_N is 0.00", "the flywheel's", "it looks like kN"]),
    # issue 43: both loads in kN read as a wheel never on the flywheel, so no check ran
    # (identify --partial wrote a flywheel inertia of 3.56 kg m² for 3563)
    ("brake_const_30bar", "vertical_load_N,longitudinal_force_N", 1e-3,
     ["vertical_load_N is 0.00", "loading.static_load_n", "it looks like kN"]),
    ("brake_osc_low", "vertical_load_N", 1e-3,
     ["vertical_load_N is 0.00", "loading.static_load_n", "it looks like kN"]),
])
def test_a_unit_within_physical_ranges_is_still_named(campaign_dir, tmp_path, capsys,
                                                      run_name, columns, factor, fragments):
    folder = _rewritten(campaign_dir, tmp_path / "campaign", run_name, columns, factor)
    assert main(["identify", str(folder), "-o", str(tmp_path / "out.yaml")]) == 2
    error = capsys.readouterr().err
    assert all(f in error for f in fragments), error
    assert f"{run_name}.csv" in error and "Traceback" not in error
    assert not (tmp_path / "out.yaml").exists()


def _pressure_rewritten(campaign_dir, folder, change):
    """The campaign with every run's pressure [bar] passed through ``change``."""
    folder.mkdir()
    for source in campaign_dir.glob("*.csv"):
        lines = source.read_text().splitlines()
        k = lines[0].split(",").index("brake_pressure_bar")
        lines = lines[:1] + [",".join(f"{change(float(v)):.12g}" if i == k else v
                                      for i, v in enumerate(line.split(",")))
                             for line in lines[1:]]
        (folder / source.name).write_text("\n".join(lines) + "\n")
    return folder


def test_an_absolute_pressure_is_named_in_the_calibrations_notes(campaign_dir, tmp_path,
                                                                 reference):
    """Issue 30: a pressure logged absolute (1.013 bar at zero current) was calibrated
    silently: dead-band −16 %, brake gain −3 %, no note."""
    folder = _pressure_rewritten(campaign_dir, tmp_path / "absolute", lambda bar: bar + 1.01325)
    result = identify(read_campaign(folder).runs, reference, jackknife=False)
    notes = [p for p in result.problems if "absolute" in p]
    assert notes and "1.01 bar at zero current" in notes[0], result.problems
    assert not [p for p in identify(read_campaign(campaign_dir).runs, reference,
                                    jackknife=False).problems if "absolute" in p]


def test_a_clipping_pressure_sensor_is_named(campaign_dir, tmp_path, reference):
    """Issue 30: a transducer that saturated at 25 bar was taken for the valve's maximum."""
    folder = _pressure_rewritten(campaign_dir, tmp_path / "clipped", lambda bar: min(bar, 25.0))
    runs = classify_all(read_campaign(folder).runs)
    notes = unit_notes(runs, reference)
    assert any("25 bar" in n and "clipp" in n for n in notes), notes
    assert unit_notes(classify_all(read_campaign(campaign_dir).runs), reference) == []


def test_a_campaign_that_cannot_identify_everything_writes_only_when_asked(campaign_dir,
                                                                         tmp_path, capsys):
    """Constant-pressure stops only: no valve steps, and a friction curve they cannot pin
    (its refinement once ended silently on its bound, ϑ3 −64 %)."""
    folder = tmp_path / "braking_only"
    folder.mkdir()
    for run in campaign_dir.glob("brake_const_*.csv"):
        shutil.copy(run, folder / run.name)
    out = tmp_path / "out.yaml"
    assert main(["identify", str(folder), "-o", str(out)]) == 2
    error = capsys.readouterr().err
    assert "not identified: valve static map; actuator dynamics A(s); friction curve" in error
    assert "--partial" in error and not out.exists()
    assert main(["identify", str(folder), "-o", str(out), "--partial"]) == 0
    text = out.read_text()
    assert text.startswith("# PARTIAL identification") and "#   valve static map" in text
    evidence = json.loads(out.with_suffix(".identification.json").read_text())
    assert evidence["not_identified"] == ["valve static map", "actuator dynamics A(s)",
                                          "friction curve"]
    assert any("drove ϑ3 to a factor 0.2" in p for p in evidence["problems"])
    assert load_parameters([out]).number("brake.gain_n_m_per_pa") > 0


def test_a_friction_parameter_the_direct_fit_puts_on_zero_is_still_refined(tmp_path,
                                                                          reference):
    """Brakes 12 % weaker keep the stops at low slip: the direct fit put ϑ3 on its zero
    bound (2.5e-10 ± 1e-24 for a rig with 0.145), and the multiplicative refinement kept it
    there. Started from the prior instead, ϑ3 comes back with an honest σ."""
    rig = rig_like(reference, np.random.default_rng(3))
    rig = rig.replace({"brake.gain_n_m_per_pa": 0.88 * rig.number("brake.gain_n_m_per_pa")},
                      "weak brakes")
    generate_campaign(tmp_path, rig, seed=4)
    estimates = {e.key: e for e in identify(read_campaign(tmp_path).runs, reference,
                                            jackknife=False).estimates}
    theta3 = estimates["friction.theta3"]
    assert theta3.std > 0.05 * theta3.value
    assert abs(theta3.value - rig.number("friction.theta3")) < 2 * theta3.std


def test_a_direct_friction_fit_that_is_no_tyres_curve_is_refined_from_the_models(reference,
                                                                                  tmp_path):
    """Slips misread by a model without the radius law, on stops at two static loads, once
    gave a direct fit of ϑ = 823, 0.93, 181: a near-straight line 35 times as stiff as a
    tyre, and every step of the output-error refinement simulated that much slower (97 s
    for one calibration). The refinement now starts from the model's curve, and says so."""
    rng = np.random.default_rng(21)
    b = reference.number("radius.b_m_per_n") * rng.uniform(1.2, 1.5)
    rig = rig_like(reference, rng).replace({"radius.b_m_per_n": b}, "a softer tyre")
    light = [f"brake_const_{bar}bar_light" for bar in LIGHT_BAR[:2]]
    generate_campaign(tmp_path, rig, 21, ["brake_const_20bar", "brake_const_30bar", *light],
                      light=True)
    start = starting_model(reference, ["load_dependent_radius"])
    result = identify(read_campaign(tmp_path).runs, start, jackknife=False)
    assert any("the direct fit is no tyre's curve" in p for p in result.problems)
    t1, t2, t3 = (result.params.number(f"friction.theta{i}") for i in (1, 2, 3))
    assert t1 < MAX_THETA1 and t1 * t2 + t3 < MAX_SLIP_STIFFNESS


def test_the_hidden_rig_passes_within_its_noise_where_a_quiet_run_fits_under_95_percent(
        campaign_dir, hidden_rig):
    """Issue 63: the 10 bar run read 93.43 % pressure fit at 0.149 bar RMSE, the logger's own
    noise, and the page had no verdict: the rig's own model now passes every channel."""
    comparisons = validate(read_campaign(campaign_dir).runs, hidden_rig)
    quiet = next(c for c in comparisons if c.measured.name == "brake_const_10bar")
    assert quiet.scores["pressure_pa"].fit_percent < 95.0
    verdicts = channel_verdicts(comparisons)
    assert [v.channel for v in verdicts] == list(CHANNELS)
    assert all(v.passed for v in verdicts), verdicts
    assert validation_sentence(verdicts).startswith("Pass: ")


def test_a_model_with_a_valve_delay_the_rig_lacks_fails_the_pressure_channel(
        campaign_dir, hidden_rig):
    late = hidden_rig.replace({"elements.actuator_delay": True, "actuator.delay_s": 0.006},
                              "a valve 6 ms late")
    verdicts = {v.channel: v for v in channel_verdicts(
        validate(read_campaign(campaign_dir).runs, late))}
    pressure = verdicts["pressure_pa"]
    assert not pressure.passed and pressure.worst.rmse > 3 * pressure.worst.noise
    assert pressure.worst.noise == pytest.approx(NOISE[K.SENSORS_PRESSURE_NOISE_PA], rel=0.2)
    assert verdicts["vertical_load_n"].passed  # the delay moves no load
    sentence = validation_sentence(list(verdicts.values()))
    assert sentence.startswith("Fail: the model misses the brake pressure on ")
    assert "actuator_steps_sweep" in pressure.failed  # the valve's steps show a delay most
    assert "bar" in sentence and "vertical load" in sentence.split(". It matches")[1]


def test_the_friction_refinement_stops_once_its_steps_no_longer_move_the_score(monkeypatch):
    """campaign_v1's refinement went on to its budget of 12 evaluations for 1e-5 of its cost
    (2.0 s of a 7.5 s diagnosis), along a floor its runs hardly tilt. Like a candidate's fit,
    it stops once a step gains less than a tenth in n_eff·ln(RSS), and what it leaves lies
    under any threshold of that unit."""
    noise = np.random.default_rng(3).normal(0.0, 1.0, 4000)

    def residuals(points):  # a wheel speed's noise beside a curved valley in ϑ1, ϑ2
        return [np.concatenate([noise, [10.0 * (u[1] - u[0] ** 2), 1.5 - u[0], u[2] - 1.0]])
                for u in points]

    def fit():
        return friction._least_squares(residuals, lambda u: None, np.ones(3),
                                       friction.REFINE_ITERATIONS)

    ours = fit()
    monkeypatch.setattr(statistics, "NEGLIGIBLE_SCORE", 0.0)
    monkeypatch.setattr(statistics, "FTOL", 1e-8)  # scipy's default, as before
    crawl = fit()
    n_eff = statistics.effective_count(residuals([crawl.x])[0])
    assert crawl.nfev == friction.REFINE_ITERATIONS and ours.nfev < crawl.nfev / 2
    assert n_eff * np.log(ours.cost / crawl.cost) < 0.5


def test_the_fits_leaving_a_run_out_start_from_the_whole_fits_rows_to_the_same_spread(
        campaign_dir, identified, monkeypatch):
    """Each leave-one-run-out fit of the friction refinement starts where the whole fit
    ended, which had simulated every run there and beside each ϑ: those rows are its
    residual and Jacobian there, to the bit, so it simulates none of them again (issue 61:
    ~80 % of `identify`'s friction simulations were the jackknife's)."""
    # three runs, the fewest a jackknife takes: both oscillating stops and one constant
    braking = [r for r in classify_all(read_campaign(campaign_dir).runs)
               if r.name in ("brake_osc_low", "brake_osc_high", "brake_const_30bar")]
    simulated = []

    def counted(run, params, *args, **kwargs):
        simulated.append(run.name)
        return simulate_run(run, params, *args, **kwargs)

    def afresh(residuals, derivatives, fit, samples):
        """The leave-one-out fits as they had run: each simulates its start again."""
        runs = range(len(samples))
        fits = [friction._least_squares(
            lambda thetas, kept=[j for j in runs if j != i]: residuals(thetas, kept),
            lambda theta: None, fit.x).x for i in runs]
        spread = np.asarray(fits) - np.mean(fits, axis=0)
        return np.sqrt((len(fits) - 1) / len(fits) * np.sum(spread ** 2, axis=0))

    monkeypatch.setattr(friction, "simulate_run", counted)
    ours = friction.refine_friction(braking, identified.params)
    spent = len(simulated)
    monkeypatch.setattr(friction, "_jackknife_std", afresh)
    before = friction.refine_friction(braking, identified.params)
    n = len(braking)
    assert n == 3 and [(e.value, e.std) for e in ours] == [(e.value, e.std) for e in before]
    # each of the n fits had simulated its n - 1 runs at its start and beside each of 3 ϑ
    assert len(simulated) - 2 * spent == 4 * n * (n - 1), (spent, len(simulated) - spent)
