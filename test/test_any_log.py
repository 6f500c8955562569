"""Any rig, any log (issue 43): a valve's step log with time, current and pressure only, a
datasheet naming what differs from the reference, one command to a verdict."""

from __future__ import annotations

import html
import json
import math

import numpy as np
import pytest
import yaml

from antiskid.metrics import braking_metrics
from landing_gear_sim.calibration.campaign import NOISE, generate_campaign, generate_run, rig_like
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.cli import main
from landing_gear_sim.diagnosis.diagnose import INCONCLUSIVE, diagnose
from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.model.runspec import build_scenario
from landing_gear_sim.report.diagnosis import write_diagnosis_report
from landing_gear_sim.report.summary import diagnosis_summary
from msg_tools.csv_io import read_csv, write_csv
from msg_tools.errors import RunFormatError
from msg_tools.io import read_campaign, read_run

SLOW_VALVE = {"actuator": {"natural_frequency_hz": 3.0, "damping_ratio": 0.9,
                           "map_k1_pa_per_a": 1.5e6, "map_k2_pa_per_a2": 3e5,
                           "max_pressure_pa": 1.2e6}}


def _three_columns(source, target) -> None:
    """``source``'s contract CSV with only time, current and pressure, as an actuator's
    logger leaves it."""
    lines = source.read_text().splitlines()
    target.write_text("\n".join(",".join(line.split(",")[:3]) for line in lines) + "\n")


def test_a_log_of_time_current_and_pressure_reads_as_an_actuator_only_run(tmp_path):
    full = tmp_path / "full"
    (path,) = generate_campaign(full, load_parameters(), 3, ["actuator_ramp"])
    three = tmp_path / "actuator_ramp.csv"
    _three_columns(path, three)
    run = read_csv(three)
    assert run.pressure_pa == pytest.approx(read_csv(path).pressure_pa)
    assert not np.any(run.wheel_speed_rad_s) and not np.any(run.vertical_load_n)
    assert any("actuator-only" in note for note in run.notes)


def _without(source, target, *columns: str) -> None:
    """``source``'s contract CSV less ``columns``, as a logger without them leaves it."""
    rows = [line.split(",") for line in source.read_text().splitlines()]
    keep = [i for i, name in enumerate(rows[0]) if name not in columns]
    target.write_text("\n".join(",".join(row[i] for i in keep) for row in rows) + "\n")


def test_a_braking_log_without_its_wheel_speed_is_refused_naming_it(tmp_path):
    (path,) = generate_campaign(tmp_path / "full", load_parameters(), 4, ["brake_const_10bar"])
    _without(path, tmp_path / "no_wheel.csv", "wheel_speed_rad_s")
    with pytest.raises(RunFormatError, match=r"wheel_speed_rad_s"):
        read_csv(tmp_path / "no_wheel.csv")


def test_a_braking_log_without_load_cells_is_read_and_its_stop_measured(tmp_path, capsys):
    """Issue 43: a brake-control engineer's anti-skid log has no load cells. It was refused
    ("missing column(s) vertical_load_N, longitudinal_force_N"); now read, its stop measured
    as the full log's, and what needs the loads (the friction used) said not logged."""
    (path,) = generate_campaign(tmp_path / "full", load_parameters(), 5, ["brake_const_30bar"])
    cut = tmp_path / "no_loads.csv"
    _without(path, cut, "vertical_load_N", "longitudinal_force_N")
    run = read_csv(cut)
    assert run.absent == ("vertical_load_n", "longitudinal_force_n")
    assert any("not logged" in note for note in run.notes)
    for name, source in (("full", path), ("cut", cut)):
        assert main(["metrics", str(source), "--json", str(tmp_path / f"{name}.json")]) == 0
    full, without = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("full", "cut"))
    assert without["stopping_distance_m"] == pytest.approx(full["stopping_distance_m"],
                                                           rel=0.01)
    assert without["slip_rms"] == pytest.approx(full["slip_rms"], rel=0.05)
    assert without["braking_efficiency"] is None and full["braking_efficiency"] > 0.3
    write_csv(run, tmp_path / "again.csv")  # written as logged: no column of NaN
    assert "vertical_load_N" not in (tmp_path / "again.csv").read_text().splitlines()[0]


def test_a_gap_while_braking_is_said_in_a_log_without_load_cells(tmp_path):
    """A gap's 'while braking' was judged from the load cell: a log without one (its load
    NaN) never braked, and a 2 s gap in its stop went unsaid."""
    (path,) = generate_campaign(tmp_path / "full", load_parameters(), 7, ["brake_const_30bar"])
    run = read_csv(path)
    on = np.flatnonzero(run.current_a > 0.5 * run.current_a.max())
    lost = round(2.0 * run.rate_hz)
    rows = path.read_text().splitlines()
    first = 1 + on[len(on) // 3]  # the header is row 0
    (tmp_path / "gap.csv").write_text("\n".join(rows[:first] + rows[first + lost:]) + "\n")
    _without(tmp_path / "gap.csv", tmp_path / "no_loads.csv", "vertical_load_N",
             "longitudinal_force_N")
    for name in ("gap", "no_loads"):
        notes = read_run(tmp_path / f"{name}.csv").notes
        assert any("2 s missing" in n and "while braking" in n for n in notes), (name, notes)


def test_a_braking_log_without_a_flywheel_encoder_is_read_and_left_out_saying_why(tmp_path):
    rig = load_parameters()
    paths = generate_campaign(tmp_path / "full", rig, 6, ["actuator_steps_sweep",
                                                          "brake_const_20bar"])
    logs = tmp_path / "logs"
    logs.mkdir()
    for path in paths:
        _without(path, logs / path.name, *(("flywheel_speed_rad_s",)
                                           if path.stem.startswith("brake") else ()))
    runs = read_campaign(logs).runs
    with pytest.raises(LandingGearSimError, match="flywheel_speed_rad_s not logged"):
        braking_metrics(next(r for r in runs if r.absent), rig)
    result = diagnose(runs, rig)
    assert any(p.startswith("brake_const_20bar: flywheel_speed_rad_s not logged: left out")
               for p in result.problems), result.problems


def test_a_slow_valves_step_log_and_its_datasheet_give_its_delay_in_one_command(tmp_path):
    """A valve 4x slower than the reference with a transport delay its datasheet lacks (the
    test draws it, 50-150 ms; the code under test sees the datasheet and two three-column
    logs): the delay is found within 10 %, held out in time on the sweep's later part."""
    sheet = tmp_path / "datasheet.yaml"
    sheet.write_text(yaml.safe_dump({"/**": {"ros__parameters": SLOW_VALVE}}))
    datasheet = load_parameters([sheet], over_reference=True)
    delay = float(np.random.default_rng(43).uniform(0.05, 0.15))
    rig = datasheet.replace({"elements.actuator_delay": True, K.ACTUATOR_DELAY_S: delay},
                            "the rig's delay")
    logs = tmp_path / "logs"
    logs.mkdir()
    for path in generate_campaign(tmp_path / "full", rig, 43,
                                  ["actuator_ramp", "actuator_steps_sweep"]):
        _three_columns(path, logs / path.name)
    result = diagnose(read_campaign(logs).runs, datasheet)
    assert result.verdict == "actuator_delay", [(f.cause, f.delta_bic, f.held_out)
                                                for f in result.candidates]
    finding = result.findings[0]
    assert finding.held_out is not None and finding.held_out < 0
    assert finding.parameters["delay_s"] == pytest.approx(delay, rel=0.1)


def _slow_datasheet(tmp_path):
    sheet = tmp_path / "datasheet.yaml"
    sheet.write_text(yaml.safe_dump({"/**": {"ros__parameters": SLOW_VALVE}}))
    return load_parameters([sheet], over_reference=True)


def _step_log(rig, folder, cycles: int, seed: int):
    """One three-column log of ``cycles`` applies and releases (held 3 s, 3 s apart) at
    levels the test picks, as a valve's step test on a bench is logged."""
    top = rig.number(K.ACTUATOR_MAX_CURRENT_A)
    profile = sc.applies_and_releases(tuple(top * (0.6, 0.35, 0.8)[k % 3]
                                            for k in range(cycles)))
    duration = 15.0 if cycles == 1 else 2.0 + 6.0 * cycles
    result = simulate(rig, sc.actuator_test(rig, profile, duration, "valve_step"))
    folder.mkdir()
    write_csv(result.to_run(noise=seed), folder / "full.csv")
    _three_columns(folder / "full.csv", folder / "valve_step.csv")
    (folder / "full.csv").unlink()
    return folder


# a release unlike the apply: stiffer while the pressure rises, [Ṗ > 1 bar/s]·ΔP, outside
# the valve library's exact terms (its sgn Ṗ·ΔP is the two-sided one)
RISING_STIFFER = basis.product_code(basis.factor_code(basis.PRESSURE_RATE, basis.STEP),
                                    basis.factor_code(basis.VALVE_ERROR, basis.IDENTITY))


def _asymmetric_slow_valve(datasheet, seed: int):
    rng = np.random.default_rng(seed)
    rig = rig_like(datasheet, rng).replace({**NOISE, "elements.actuator_delay": True}, "noise")
    delay, stiffer = rng.uniform(0.05, 0.15), rng.uniform(0.4, 0.8)
    return rig.replace({K.ACTUATOR_DELAY_S: delay, K.VALVE_TERMS[0][0]: float(RISING_STIFFER),
                        K.VALVE_TERMS[0][1]: stiffer}, "hidden effect"), delay


def test_a_step_log_of_a_slow_valve_gives_its_delay_and_a_release_unlike_its_apply(tmp_path):
    """Issue 43's benchmark case as a test: one step log (three applies and releases) of a
    valve 4x slower than the reference, its map ±3 % off its datasheet, a 50-150 ms delay
    and a release unlike its apply, drawn here. Its later steps are held out in time: they
    had been simulated from zero pressure in the middle of a hold (18 bar off at their
    first sample), and the map was the datasheet's (no ramp run)."""
    datasheet = _slow_datasheet(tmp_path)
    rig, delay = _asymmetric_slow_valve(datasheet, 51)
    runs = read_campaign(_step_log(rig, tmp_path / "logs", 3, 51)).runs
    result = diagnose(runs, datasheet)
    causes = {f.cause: f for f in result.findings}
    assert result.verdict == "actuator_delay", [(f.cause, f.delta_bic, f.held_out, f.reason)
                                                for f in result.candidates]
    assert causes["actuator_delay"].parameters["delay_s"] == pytest.approx(delay, rel=0.1)
    # a release unlike the apply is the named family's (issue 60), stiffer applying
    valve = causes.get("discovered")
    assert valve is not None and valve.family == "valve_direction", result.findings
    assert valve.parameters.get("sgn ΔP·ΔP", 0.0) > 0.0, valve.term
    assert valve.held_out is not None and valve.held_out < 0
    assert valve.fit_after["pressure_pa"] >= 96.0  # the later steps, as held out (were 91 %)
    # the calibration's note that the model lacks a delay is answered by the verdict
    assert not any("later than A(s) alone can" in p for p in result.problems), result.problems
    # a candidate whose model diverged on the held-out part (nan) had met every rule
    assert all(math.isfinite(f.held_out) for f in result.candidates
               if f.accepted and f.held_out is not None)


def test_a_log_of_one_apply_and_one_release_proposes_the_run_that_settles_it(tmp_path):
    """One apply and one release of that valve: the delay fitted on the apply cannot be
    checked on a release unlike it; the verdict is inconclusive and says so. It proposes a
    wheel-off run (the log has no wheel) that tells the delay from none; that run, made by
    the same valve and logged as the first, settles it (issue 64, item 3)."""
    datasheet = _slow_datasheet(tmp_path)
    rig, delay = _asymmetric_slow_valve(datasheet, 52)
    logs = _step_log(rig, tmp_path / "logs", 1, 52)
    result = diagnose(read_campaign(logs).runs, datasheet)
    assert result.verdict == INCONCLUSIVE
    assert any("one more step" in p and "actuator_delay" in p for p in result.problems), \
        result.problems
    proposed = result.next_run
    assert proposed is not None and proposed.settles, proposed
    assert "actuator_delay" in proposed.explanations and proposed.equation == "valve"
    assert proposed.proposal.spec.profile in ("steps", "sweep", "ramp")
    path = generate_run(tmp_path / "next", rig, build_scenario(proposed.proposal.spec, rig), 52)
    _three_columns(path, logs / path.name)
    settled = diagnose(read_campaign(logs).runs, datasheet)
    assert settled.verdict == "actuator_delay", settled.verdict
    assert settled.findings[0].parameters["delay_s"] == pytest.approx(delay, rel=0.05)


def test_a_step_log_without_a_ramp_reads_the_valves_map_from_its_held_levels(tmp_path):
    datasheet = _slow_datasheet(tmp_path)
    k1 = datasheet.number(K.ACTUATOR_MAP_K1_PA_PER_A) * np.random.default_rng(53).uniform(
        1.04, 1.08)
    rig = datasheet.replace({**NOISE, K.ACTUATOR_MAP_K1_PA_PER_A: k1}, "the rig's map")
    calibration = identify(read_campaign(_step_log(rig, tmp_path / "logs", 3, 53)).runs,
                           datasheet, friction=False, jackknife=False)
    assert calibration.params.number(K.ACTUATOR_MAP_K1_PA_PER_A) == pytest.approx(k1,
                                                                                  rel=0.01)
    assert not any("static map" in p for p in calibration.problems), calibration.problems


def test_a_part_cut_mid_hold_starts_where_the_valve_was_and_a_log_at_rest_at_rest():
    """A part of a run cut in time starts mid-hold: its simulation had started at zero
    pressure, 18 bar off, behind a delay whose register made the settling stop at once. A
    sweep whose first sample commands a step starts at rest, as the rig did (U02's)."""
    from landing_gear_sim.calibration.measured import simulate_run
    from landing_gear_sim.calibration.runs import classified

    rig = load_parameters().replace({"elements.actuator_delay": True,
                                     K.ACTUATOR_DELAY_S: 0.08}, "a delay")
    level = 0.5 * rig.number(K.ACTUATOR_MAX_CURRENT_A)
    logged = simulate(rig, sc.actuator_test(rig, sc.constant(level), 4.0)).to_run()
    assert logged.pressure_pa[0] == 0.0 and logged.pressure_pa[-1] > 1e6
    part = classified(logged.part(slice(2000, None), "held (after)"))
    whole = classified(logged)
    assert simulate_run(part, rig)[0].pressure_pa[0] == pytest.approx(part.pressure_pa[0],
                                                                      rel=1e-6)
    assert simulate_run(whole, rig)[0].pressure_pa[0] == 0.0


def test_what_reading_said_is_a_note_and_only_an_unread_file_is_skipped(tmp_path):
    """The CLI printed 'skipped: … an actuator-only log, read with the wheel off the
    flywheel' for a log it had read."""
    (path,) = generate_campaign(tmp_path / "full", load_parameters(), 7, ["actuator_ramp"])
    logs = tmp_path / "logs"
    logs.mkdir()
    _three_columns(path, logs / "actuator_ramp.csv")
    (logs / "broken.csv").write_text("time_s,current_ref_A\n0,1\n")
    said = read_campaign(logs).said()
    assert any(s.startswith("note: ") and "actuator-only" in s for s in said), said
    assert any(s.startswith("skipped: ") and "broken.csv" in s for s in said), said
    assert len(said) == 2


def test_a_single_stop_proposes_the_run_that_settles_it(tmp_path):
    """Issue 43, a campaign of one run: a braking run is one piece, never cut in time, so
    what it fits better cannot be checked; the note names the run one more like it would
    settle (it had said 'too little held-out data for a verdict')."""
    rig = rig_like(load_parameters(), np.random.default_rng(57)).replace(
        {"elements.tire_relaxation": True,
         K.TYRE_RELAXATION_LENGTH_M: float(np.random.default_rng(58).uniform(0.4, 0.8))},
        "hidden effect")
    generate_campaign(tmp_path, rig, 57, ["brake_const_30bar"])
    result = diagnose(read_campaign(tmp_path).runs, load_parameters())
    assert result.verdict == INCONCLUSIVE, result.verdict
    assert any("tire_relaxation" in p and "one more run like brake_const_30bar would settle"
               in p for p in result.problems), result.problems
    # the run it proposes (a stop at constant pressure: what the relaxation is fitted on),
    # made by the same rig, settles it (issue 64, item 3)
    proposed = result.next_run
    assert proposed is not None and proposed.settles, proposed
    assert proposed.explanations[0] == "the model as calibrated"
    assert "tire_relaxation" in proposed.explanations
    assert proposed.proposal.spec.profile == "constant" and proposed.equation == "tyre"
    said = proposed.sentence()
    assert result.to_json()["next_run"]["command"] in said  # type: ignore[index]
    assert said[1:] in diagnosis_summary(result)  # its first letter a capital there
    page = write_diagnosis_report(result, tmp_path / "report").read_text()
    assert html.escape(said[1:]) in page.split("<details")[0]  # on the first screen
    generate_run(tmp_path, rig, build_scenario(proposed.proposal.spec, rig), 57)
    settled = diagnose(read_campaign(tmp_path).runs, load_parameters())
    assert settled.verdict == "tire_relaxation", settled.verdict
    assert settled.findings[0].parameters["relaxation_length_m"] == pytest.approx(
        rig.number(K.TYRE_RELAXATION_LENGTH_M), rel=0.05)


def _slow_valve_with_delay(datasheet, seed: int):
    """A valve like the slow datasheet's (±5 % on ω_n and ζ) with a delay of 50-150 ms,
    each drawn here."""
    rng = np.random.default_rng(seed)
    truth = {K.ACTUATOR_NATURAL_FREQUENCY_HZ: datasheet.number(
                 K.ACTUATOR_NATURAL_FREQUENCY_HZ) * rng.uniform(0.95, 1.05),
             K.ACTUATOR_DAMPING_RATIO: datasheet.number(K.ACTUATOR_DAMPING_RATIO)
             * rng.uniform(0.95, 1.05),
             K.ACTUATOR_DELAY_S: rng.uniform(0.05, 0.15)}
    rig = datasheet.replace({**NOISE, "elements.actuator_delay": True, **truth}, "the valve")
    return rig, truth


def test_identify_fits_the_delay_a_datasheet_says_the_valve_has(tmp_path):
    """Issue 43: identify fitted ω_n and ζ of a step log with the delay held where the
    datasheet put it (or left out): a 4x slower valve's ω_n read 1.98 Hz for 2.98."""
    rig, truth = _slow_valve_with_delay(_slow_datasheet(tmp_path), 54)
    datasheet = _slow_datasheet(tmp_path).replace(
        {"elements.actuator_delay": True, K.ACTUATOR_DELAY_S: 0.02}, "datasheet: a delay")
    calibration = identify(read_campaign(_step_log(rig, tmp_path / "logs", 3, 54)).runs,
                           datasheet, friction=False, jackknife=False)
    for key, value in truth.items():
        assert calibration.params.number(key) == pytest.approx(value, rel=0.1), key
    assert any(e.key == K.ACTUATOR_DELAY_S for e in calibration.estimates)


def test_identify_says_a_delay_the_model_lacks_and_what_it_costs_the_valves_dynamics(
        tmp_path):
    """Without a delay in the model, ω_n and ζ absorb the valve's dead time; identify says
    how late the valve answers and where a delay is tested."""
    rig, truth = _slow_valve_with_delay(_slow_datasheet(tmp_path), 55)
    calibration = identify(read_campaign(_step_log(rig, tmp_path / "logs", 3, 55)).runs,
                           _slow_datasheet(tmp_path), friction=False, jackknife=False)
    (note,) = [p for p in calibration.problems if "later than A(s)" in p]
    late_ms = float(note.split(" ms later than A(s)")[0].split()[-1])
    assert late_ms == pytest.approx(1e3 * truth[K.ACTUATOR_DELAY_S], rel=0.15), note
    assert "actuator_delay" in note and "diagnose" in note


def test_a_step_log_of_another_valve_without_a_datasheet_takes_its_map_from_the_holds(
        tmp_path, reference, capsys):
    """Issue 64: a real valve's step log read without a datasheet was refused with
    'brake_pressure_bar is 0.154 times what the valve map gives for its current; check its
    unit'. 0.154 is no unit's factor: another valve, whose map the log's held levels give,
    and a note says so."""
    from landing_gear_sim.cli import main

    share = float(np.random.default_rng(64).uniform(0.12, 0.2))  # drawn here
    rig = reference.replace({**NOISE, K.ACTUATOR_MAP_K1_PA_PER_A:
                             share * reference.number(K.ACTUATOR_MAP_K1_PA_PER_A),
                             K.ACTUATOR_MAP_K2_PA_PER_A2:
                             share * reference.number(K.ACTUATOR_MAP_K2_PA_PER_A2)}, "valve")
    folder = _step_log(rig, tmp_path / "logs", 3, 64)
    assert main(["identify", str(folder), "--partial", "-o", str(tmp_path / "valve.yaml")]) == 0
    said = "".join(capsys.readouterr())
    assert "held levels of the step log" in said and "another valve" in said, said
    calibrated = load_parameters([tmp_path / "valve.yaml"], over_reference=True)
    assert calibrated.number(K.ACTUATOR_MAP_K1_PA_PER_A) == pytest.approx(
        rig.number(K.ACTUATOR_MAP_K1_PA_PER_A), rel=0.05)


def test_a_datasheet_parameter_at_zero_does_not_end_the_diagnosis(tmp_path, capsys):
    """Issue 64: a datasheet naming the valve with a dead-band of 0 ended the diagnosis at
    'fitting a discovered term: valve' with "parameter 'actuator.deadband_current_a' must be
    finite, got nan", exit 2: a free parameter at 0 had a window of 0.5-2 times 0, and the
    fit's unit box divided by its width."""
    from landing_gear_sim.cli import main

    sheet = {"actuator": {"deadband_current_a": 0.0, "map_k1_pa_per_a": 9e5,
                          "max_pressure_pa": 6e5, "natural_frequency_hz": 2.0,
                          "damping_ratio": 0.9}, "elements": {"actuator_delay": True}}
    (tmp_path / "sheet.yaml").write_text(yaml.safe_dump({"/**": {"ros__parameters": sheet}}))
    datasheet = load_parameters([tmp_path / "sheet.yaml"], over_reference=True)
    rng = np.random.default_rng(641)
    release = rng.uniform(2.0, 4.0)  # the exhaust this many times as fast as the inlet
    by_port = basis.product_code(basis.factor_code(basis.VALVE_ERROR, basis.SIGN),
                                 basis.factor_code(basis.VALVE_ERROR, basis.IDENTITY))
    rig = datasheet.replace({**NOISE, K.ACTUATOR_NATURAL_FREQUENCY_HZ: 3.0,
                             K.ACTUATOR_MAP_K1_PA_PER_A: 9.5e5,
                             K.ACTUATOR_DELAY_S: rng.uniform(0.05, 0.12),
                             K.VALVE_TERMS[0][0]: float(by_port),
                             K.VALVE_TERMS[0][1]: (1 - release ** 2) / (1 + release ** 2)},
                            "the rig")
    folder = _step_log(rig, tmp_path / "logs", 1, 641)
    assert main(["diagnose", str(folder), "--config", str(tmp_path / "sheet.yaml")]) == 0, \
        capsys.readouterr().err
