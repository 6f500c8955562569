"""Trust (issue 28): the right verdict on data as real loggers write it, and a verdict that
tells one consistent story.

Each test hides, in a campaign of the project's own generator (parameters drawn by the test,
unseen by the code under test), a failure class first measured on campaigns of an
independent simulator: logger realities on nulls, a cause replaced or joined by findings it
explains already, a lag nothing in the rig has.
"""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like, standard_scenarios
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.logger import Logger
from landing_gear_sim.calibration.measured import CHANNELS, simulate_all
from landing_gear_sim.calibration.plausibility import unit_notes
from landing_gear_sim.calibration.runs import classify_all
from landing_gear_sim.diagnosis.catalogue import (
    fade_reach,
    gear_walk_key_parameters,
    noise_scales,
)
from landing_gear_sim.diagnosis.consistency import check_campaign
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.diagnosis.equations import Equation
from landing_gear_sim.diagnosis.equations.placing import EquationError, locate
from landing_gear_sim.diagnosis.families import HIDDEN, Evidence, gain_law
from landing_gear_sim.diagnosis.findings import Signature, SignatureKind
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.diagnosis.scoring import BIC_THRESHOLD, score_candidate
from landing_gear_sim.diagnosis.signatures import find_signatures, unexplained
from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.sensors import SensorModel, wheel_angle_rad
from msg_tools.io import read_campaign

# a short campaign keeps the suite quick: the valve's runs and four stops
RUNS = ("actuator_ramp", "actuator_steps_sweep", "brake_const_30bar", "brake_const_40bar",
        "brake_osc_low", "brake_osc_high")
BRAKING = ("brake_const_30bar", "brake_const_40bar", "brake_osc_low", "brake_osc_high")

LOGGERS = {
    "a 64-line counting encoder": Logger(encoder_counts=64),
    "a 256-line counting encoder": Logger(encoder_counts=256),
    "200 Hz, no anti-alias filter": Logger(rate_hz=200.0),
    "2 kHz": Logger(rate_hz=2000.0),
    "10 mA on the current, 12-bit ADC": Logger(current_noise_a=0.01, current_adc_bits=12),
}


def _campaign(reference, folder, seed, effect=None, logger=None, names=RUNS):
    rng = np.random.default_rng(seed)
    rig = rig_like(reference, rng)
    if effect is not None:
        rig = rig.replace(effect(rng), "hidden effect")
    generate_campaign(folder, rig, seed, names, logger=logger)
    campaign = read_campaign(folder)
    return campaign.runs, rig


def _consistent(result):
    """The verdict is the best finding's cause, and nothing is reported twice."""
    if result.findings:
        assert result.verdict == result.findings[0].cause
    else:
        assert result.verdict in ("none", "inconclusive")
    return result


@pytest.mark.parametrize("logger", LOGGERS.values(), ids=LOGGERS.keys())
def test_under_the_model_that_made_it_a_campaign_as_loggers_write_it_shows_no_signature(
        reference, tmp_path, logger):
    """The residual of the true model is noise, however the logger wrote it: no regressor
    built from the channel under test (slip read from the noisy wheel channel correlated
    with its own noise: r = −0.77 on a counting encoder), no lag the log cannot resolve."""
    runs, rig = _campaign(reference, tmp_path, 201, logger=logger, names=BRAKING)
    runs = classify_all(runs)
    found = find_signatures(runs, rig, simulate_all(runs, rig))
    assert found == [], [s.describe() for s in found]


def test_a_null_campaign_read_by_a_counting_encoder_is_none(reference, tmp_path):
    runs, _ = _campaign(reference, tmp_path, 202, logger=Logger(encoder_counts=64))
    result = _consistent(diagnose(runs, reference))
    assert result.verdict == "none", [f.evidence for f in result.findings]


def test_a_null_logged_at_200_hz_through_a_noisy_adc_is_none_and_says_what_it_cannot_tell(
        reference, tmp_path):
    """Issue 41, nulls: a current logged at 200 Hz with 6.7 mA of noise through a 12-bit ADC
    (fed to the model as logged, or through a 5-sample median) moves the model's pressure by
    10-20 kPa rms; A(s)'s √ΔP read 12.6 kPa of it at 7σ and the null came out `unexplained
    (valve)`. A valve's second stage reads the same there (12-35 kPa at 6-16σ): the check
    still calls for the valve's terms, the scoring judges them, and what is left within the
    current's noise is said, not reported as structure."""
    logger = Logger(rate_hz=200.0, current_noise_a=0.00669199, current_adc_bits=12)
    runs, _ = _campaign(reference, tmp_path, 3066, logger=logger, names=None)
    result = _consistent(diagnose(runs, reference))
    assert result.verdict == "none", [f.evidence for f in result.findings]
    assert any("A(s)" in p and "noise in the model's inputs" in p for p in result.problems), \
        result.problems
    within = [c.to_json() for c in result.consistency
              if c.relation == Relation.VALVE_DYNAMICS and c.violated]
    assert within and all(c["input_noise"] > abs(c["deviation"]) for c in within), within


def _relaxing(rng):
    return {"elements.tire_relaxation": True, "tyre.relaxation_length_m": rng.uniform(0.2, 0.8)}


FRICTION = ("friction.theta1", "friction.theta2", "friction.theta3")


def test_a_model_told_the_tyre_relaxes_calibrates_the_rigs_friction_curve(reference, tmp_path):
    """Issue 41: a rig whose tyre relaxes over 0.69 m was calibrated to ϑ = 2.34, 14.5, 2.32
    (its own 0.97, 27.6, 0.15) with the relaxation in the model or not: the filtered wheel
    speed, lagging a wheel spinning up near the stop, read slips down to −0.13, where the
    curve is −32; the model with the true relaxation then lost to three tyre terms."""
    runs, rig = _campaign(reference, tmp_path, 3174, _relaxing, names=None)
    told = reference.replace({"elements.tire_relaxation": True,
                              "tyre.relaxation_length_m": 0.69}, "the relaxation found")
    calibrated = identify(runs, told, jackknife=False).params
    for key, tolerance in zip(FRICTION, (0.05, 0.05, 0.5), strict=True):
        assert calibrated.number(key) == pytest.approx(rig.number(key), rel=tolerance), key


def test_a_relaxing_tyre_logged_at_200_hz_is_named_not_replaced_by_tyre_terms(reference,
                                                                             tmp_path):
    """Issue 41: the sweep's relaxation 3174, logged at 200 Hz, came out `discovered tyre`
    (μ_B·√λ, μ_B³, μ_B·v), the relaxation found at 0.686 m for a drawn 0.686 m and then
    replaced: the re-calibrated model it was in had a friction curve bent by a lagging
    wheel reading (see the test above)."""
    runs, rig = _campaign(reference, tmp_path, 3174, _relaxing, logger=Logger(rate_hz=200.0),
                          names=None)
    result = _consistent(diagnose(runs, reference))
    assert result.verdict == "tire_relaxation", [f.evidence for f in result.findings]
    (found,) = [f for f in result.findings if f.cause == "tire_relaxation"]
    assert found.parameters["relaxation_length_m"] == pytest.approx(
        rig.number("tyre.relaxation_length_m"), rel=0.2)


def test_a_brake_fade_is_named_with_no_violated_relation_beside_it(reference, tmp_path):
    """The gain relations are judged against the model's whole gain law, its fade included:
    a fade the model has explained is no violated 'brake gain constant in speed'."""
    runs, rig = _campaign(reference, tmp_path, 203, lambda rng: {
        "elements.brake_fade": True, "brake.fade_fraction": rng.uniform(0.12, 0.2),
        "brake.fade_energy_j": rng.uniform(1.5e6, 2.5e6)}, names=None)
    result = _consistent(diagnose(runs, reference))
    assert [f.cause for f in result.findings] == ["brake_fade"], \
        [f.evidence for f in result.findings]
    assert result.findings[0].parameters["fade_fraction"] == pytest.approx(
        rig.number("brake.fade_fraction"), rel=0.2)
    assert not any(c.violated for c in result.consistency)


def test_logger_realities_are_named_in_words_and_bad_ones_refused():
    logger = Logger.parse("rate_hz=200,encoder_counts=64,late=pressure_pa:0.005")
    assert logger == Logger(rate_hz=200.0, encoder_counts=64, late_channel="pressure_pa",
                            late_s=0.005)
    assert logger.realities == ["logged at 200 Hz", "wheel speed from a 64-count encoder",
                                "pressure_pa logged 5 ms late"]
    assert Logger().realities == []
    for bad in ("rate=200", "late=current_a:0.01", "dropout_s=-1", "encoder_counts=x"):
        with pytest.raises(ParameterError):
            Logger.parse(bad)


@pytest.mark.parametrize("effect", [
    {"sensors.wheel_speed_delay_s": 0.012},
    {"sensors.wheel_runout_1": 0.03, "sensors.wheel_runout_1_phase_rad": 0.7},
], ids=["a late wheel channel", "an encoder rippling once a revolution"])
def test_a_counting_encoder_counts_the_lines_of_what_its_channel_reads(reference, effect):
    """A counting encoder's wheel speed keeps what the wheel channel's own effects do: it
    counts the lines of the channel's angle (late when the channel is late; an eccentric
    disc's lines where a rippling channel puts them). Counting the true wheel's lines had
    erased a hidden wheel skew or ripple from every campaign logged through an encoder."""
    rig = reference.replace(effect, "hidden effect")
    result = simulate(rig, standard_scenarios(rig)["brake_const_30bar"])
    line = 2.0 * np.pi / 256
    logged = Logger(encoder_counts=256).write(result, result.to_run(),
                                              np.random.default_rng(3))
    channel = SensorModel.of(rig).wheel_speed(result.time_s, result.wheel_speed_rad_s)
    counted = np.cumsum(logged.wheel_speed_rad_s[1:] * np.diff(logged.time_s))
    read = wheel_angle_rad(result.time_s, channel)[1:]
    true = wheel_angle_rad(result.time_s, result.wheel_speed_rad_s)[1:]
    assert np.max(np.abs(counted - read)) <= 1.01 * line
    assert np.max(np.abs(counted - true)) > 2.0 * line


@pytest.mark.parametrize("lines", [64, 256])
def test_a_counted_wheel_channel_is_named_with_its_resolution(reference, tmp_path, lines):
    """Through 64 lines a 5.6 ms wheel skew or a 2 % encoder ripple read 'none' with nothing
    said of why: the encoder's resolution, estimated from the data, is in the notes."""
    runs, _ = _campaign(reference, tmp_path, 214, logger=Logger(encoder_counts=lines),
                        names=BRAKING)
    notes = unit_notes(classify_all(runs), reference)
    assert any(f"{lines} lines per revolution" in n for n in notes), notes


COUNTERS = {"64 lines at 1 kHz": Logger(encoder_counts=64),
            "64 lines at 2 kHz": Logger(rate_hz=2000.0, encoder_counts=64),
            "256 lines at 1 kHz": Logger(encoder_counts=256),
            "128 lines at 500 Hz": Logger(rate_hz=500.0, encoder_counts=128)}


@pytest.mark.parametrize("logger", COUNTERS.values(), ids=COUNTERS.keys())
def test_a_counted_wheel_channel_is_judged_by_its_counters_noise_without_false_alarms(
        reference, tmp_path, logger):
    """The free-rolling ripple check through a counter, under the model that made the
    campaign: a σ of the counter's own (64 lines at 2 kHz: white noise gave 0.45 % where the
    counter's error, cancelling over whole revolutions, is ~0.1 %) that stays honest: no
    check beyond 4σ, none violated."""
    runs, rig = _campaign(reference, tmp_path, 301, logger=logger, names=BRAKING)
    checks = [c for c in check_campaign(classify_all(runs), rig)
              if c.relation == Relation.WHEEL_ANGLE]
    assert len(checks) == len(BRAKING)
    assert all(c.z < 4 and not c.violated for c in checks), [c.describe() for c in checks]
    assert max(c.std for c in checks) < 0.002


def test_a_hyperbolic_fade_is_measured_with_its_shape(reference, tmp_path):
    """A fade that saturates as E/(E + E_f) (an independent rig's law) read as 11 % for
    15 % through the exponential alone: the fade's shape is identified with it."""
    runs, rig = _campaign(reference, tmp_path, 205, lambda rng: {
        "elements.brake_fade": True, "brake.fade_fraction": rng.uniform(0.12, 0.2),
        "brake.fade_energy_j": rng.uniform(1.5e6, 2.5e6), "brake.fade_shape": 1.0},
        names=None)
    result = _consistent(diagnose(runs, reference))
    assert result.verdict == "brake_fade", [f.evidence for f in result.findings]
    found = result.findings[0].parameters
    assert found["fade_fraction"] == pytest.approx(rig.number("brake.fade_fraction"), rel=0.1)
    assert found["fade_shape"] > 0.5


def test_a_fade_energy_beyond_what_any_run_absorbs_is_out_of_reach(reference, tmp_path):
    """φ 0.8 % at E_f = 700 MJ was once accepted as a fade: a stop absorbs a few MJ, so the
    runs only show a law in brake energy's first slope."""
    runs, rig = _campaign(reference, tmp_path, 206, names=("brake_const_30bar",))
    runs = classify_all(runs)
    reason = fade_reach({"brake.fade_energy_j": 7e8}, runs, rig)
    assert reason.startswith("its fade energy 700 MJ lies beyond what the runs exercise")
    assert fade_reach({"brake.fade_energy_j": 2e6}, runs, rig) == ""


def test_a_disc_run_out_is_discovered_in_the_wheel_angle_family(reference, tmp_path):
    """A brake torque that ripples once per wheel revolution (an independent rig's 5 %
    run-out gave 'unexplained', a 7.8 Hz line): the wheel_angle family, its size measured,
    read in the torque balance while the brake acts (the free rolling shows nothing)."""
    runs, rig = _campaign(reference, tmp_path, 207, lambda rng: {
        "brake.runout_1": rng.uniform(0.02, 0.08),
        "brake.runout_1_phase_rad": rng.uniform(-np.pi, np.pi)})
    result = _consistent(diagnose(runs, reference))
    assert result.verdict == "discovered", [f.evidence for f in result.findings]
    finding = result.findings[0]
    assert finding.family == "wheel_angle" and finding.term.startswith("T_b = ")
    assert finding.parameters["brake_runout_1"] == pytest.approx(
        rig.number("brake.runout_1"), rel=0.1)
    assert finding.held_out is not None and finding.held_out < -10


def test_a_pressure_channel_logged_late_is_its_skew_not_an_actuator_delay(reference, tmp_path):
    """A pressure channel stamped 5 ms late once gave an actuator delay of 5 ms and beside
    it a wheel 'leading' by 5.7 ms: the torque the brake makes leads the measured pressure,
    which a valve's delay cannot do, so the story is the channel's skew alone."""
    late = float(np.random.default_rng(208).uniform(0.004, 0.012))
    runs, _ = _campaign(reference, tmp_path, 208, logger=Logger(
        late_channel="pressure_pa", late_s=late))
    result = _consistent(diagnose(runs, reference))
    assert [(f.cause, f.family) for f in result.findings] == [("discovered", "channel_skew")], \
        [f.evidence for f in result.findings]
    finding = result.findings[0]
    assert finding.term.startswith("P_read(t) = P(t − ")
    assert finding.parameters["pressure_delay_s"] == pytest.approx(late, abs=1e-3)
    assert "brake torque in step with the measured pressure" in finding.evidence


def test_a_dropout_in_every_run_loses_no_run_and_the_delay_is_measured(reference, tmp_path):
    """One 50 ms dropout per run once split every run and lost the stops' second halves;
    the 8 ms delay came out 5.8 ms. The gaps are bridged and left out of the comparisons."""
    runs, rig = _campaign(reference, tmp_path, 209, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": rng.uniform(0.004, 0.012)},
        logger=Logger(dropout_s=0.05))
    assert sorted(r.name for r in runs) == sorted(RUNS)
    result = _consistent(diagnose(runs, reference))
    assert result.verdict == "actuator_delay", [f.evidence for f in result.findings]
    assert result.findings[0].parameters["delay_s"] == pytest.approx(
        rig.number("actuator.delay_s"), abs=1e-3)


def test_a_line_is_placed_in_the_equation_whose_error_carries_it():
    """'Unexplained' says where: a 7.8 Hz line once reported in the wheel-speed residual
    lived in another equation. The equation whose own error (from the measured signals)
    carries the line most strongly is named."""
    rng = np.random.default_rng(210)
    t = np.arange(8000) / 1000.0

    def errors(run, line_in):
        return [EquationError(e, run, rng.normal(0.0, 1.0, t.size)
                              + (0.8 * np.sin(2 * np.pi * 7.8 * t) if e is line_in else 0.0),
                              1000.0) for e in Equation]

    found = [*errors("a", Equation.FLYWHEEL), *errors("b", Equation.FLYWHEEL)]
    line = Signature(SignatureKind.FREQUENCY, "wheel_speed_rad_s", 7.8, 40.0, ("a", "b"))
    place = locate(line, found)
    assert place is not None and place.equation is Equation.FLYWHEEL
    assert place.strength[Equation.FLYWHEEL] > 10 * place.strength[Equation.WHEEL]
    assert "flywheel" in place.describe()
    finding = unexplained([line], {}, [place])
    assert finding.equation == "flywheel" and finding.channel == "wheel_speed_rad_s"
    lag = Signature(SignatureKind.LAG, "wheel_speed_rad_s", 0.02, 20.0, ("a", "b"))
    assert locate(lag, found) is None and unexplained([lag], {}).equation == "wheel channel"


def test_a_valve_with_play_is_discovered_through_a_noisy_quantised_current(reference,
                                                                           tmp_path):
    """10 mA of noise and a 12-bit ADC on the logged current made every sample a 'fast'
    current change (the valve-direction relation went unchecked: 'none'), and fed to the
    model the noise kicked the play both ways. The ramp is fed its denoised command and
    the direction read from the current's slope."""
    runs, rig = _campaign(reference, tmp_path, 211, lambda rng: {
        "actuator.backlash_a": rng.uniform(0.01, 0.04)},
        logger=Logger(current_noise_a=0.007, current_adc_bits=12))
    result = _consistent(diagnose(runs, reference))
    assert (result.verdict, result.findings[0].family) == ("discovered", "input_history"), \
        [f.evidence for f in result.findings]
    assert result.findings[0].parameters["backlash_a"] == pytest.approx(
        rig.number("actuator.backlash_a"), rel=0.2)


def test_a_gear_walk_read_through_a_coarse_encoder_is_named(reference, tmp_path):
    """A 256-line encoder's wheel speed is noise at the gear walk's scale: the gear walk
    gained 0.01 points of wheel fit and 0.18 of F_x, and the mean of the two, under 0.1,
    called it not worth having. The channel it helps most decides."""
    runs, rig = _campaign(reference, tmp_path, 1070, lambda rng: {
        "gear_walk.stiffness_n_m_per_rad": 6.9e5 * rng.uniform(0.6, 1.5)},
        logger=Logger(encoder_counts=256), names=None)
    result = _consistent(diagnose(runs, reference, without=["gear_walk"]))
    assert result.verdict == "gear_walk", [(f.cause, f.fit_before, f.fit_after)
                                           for f in result.candidates]
    assert result.findings[0].parameters["frequency_hz"] == pytest.approx(
        gear_walk_key_parameters(rig)["frequency_hz"], rel=0.05)


def test_a_wheel_channel_skew_read_through_a_counting_encoder_is_discovered(reference,
                                                                           tmp_path):
    """A wheel channel logged late through a 256-line encoder (the skew drawn by the test):
    the term fitted the skew within 0.4 ms and predicted the held-out runs better (by 179 in
    log-likelihood), but gained 0.09 points of the wheel's fit, which the encoder's counting
    noise dominates, and was called not worth having ('unexplained'; 'none' on another
    campaign). Worth is judged on what the logger's noise leaves of the channel as well."""
    runs, rig = _campaign(reference, tmp_path, 213, lambda rng: {
        "sensors.wheel_speed_delay_s": rng.uniform(0.004, 0.008)},
        logger=Logger(encoder_counts=256))
    result = _consistent(diagnose(runs, reference))
    assert (result.verdict, result.findings[0].family) == ("discovered", "channel_skew"), \
        [(f.cause, f.family, f.evidence) for f in result.candidates]
    assert result.findings[0].parameters["wheel_speed_delay_s"] == pytest.approx(
        rig.number("sensors.wheel_speed_delay_s"), abs=1e-3)
    assert result.findings[0].held_out is not None and result.findings[0].held_out < -10


def test_a_wheel_channel_skew_read_through_a_64_line_encoder_is_discovered(reference,
                                                                          tmp_path):
    """A wheel channel logged late through a 64-line encoder (98 rad/s per count; the skew
    drawn by the test): the stops at constant pressure decelerate smoothly, so their
    counted speed holds no timing, and read 0.0 ms or ±14 ms; outvoting the cycling stops
    (21 and 10 ms), they left no lag, no candidate and the verdict 'none'. Only a stop
    whose transitions stand out of the counting noise tells a channel's timing."""
    runs, rig = _campaign(reference, tmp_path, 1222, lambda rng: {
        "sensors.wheel_speed_delay_s": rng.uniform(0.01, 0.025)},
        logger=Logger(encoder_counts=64), names=None)
    result = _consistent(diagnose(runs, reference))
    assert [(f.cause, f.family) for f in result.findings[:1]] == [
        ("discovered", "channel_skew")], [(f.cause, f.family, f.evidence)
                                          for f in result.candidates]
    assert result.findings[0].parameters["wheel_speed_delay_s"] == pytest.approx(
        rig.number("sensors.wheel_speed_delay_s"), abs=1.5e-3)


def _ripple_resolution(problems):
    [note] = [p for p in problems if p.startswith(f"{Relation.WHEEL_ANGLE}: ")]
    return float(note.split(" below ")[1].split(" %")[0]) / 100


def test_a_counted_wheel_channel_says_which_ripple_it_cannot_resolve(reference, tmp_path):
    """A ripple twice per revolution (0.64 % of ω) read through a 64-line encoder at 2 kHz
    (196 rad/s per count): its free-rolling checks read 0.48-0.85 % ± 0.45 % per run, so
    'none' was all a user saw, and then a bound of 2.7 %, four times what the counter hides
    (its error cancels over whole revolutions: 0.13 % at twice per revolution). The bound
    is the counter's own now and covers the ripple that did not show; a ripple of twice
    the bound, in the same campaign, is named in the wheel channel with its size."""
    logger = Logger(rate_hz=2000.0, encoder_counts=64)
    small, hidden = _campaign(reference, tmp_path / "small", 1188, lambda rng: {
        "sensors.wheel_runout_2": rng.uniform(0.003, 0.008),
        "sensors.wheel_runout_2_phase_rad": rng.uniform(-np.pi, np.pi)},
        logger=logger, names=None)
    result = _consistent(diagnose(small, reference))
    assert result.verdict == "none", [f.evidence for f in result.findings]
    bound = _ripple_resolution(result.problems)
    assert hidden.number("sensors.wheel_runout_2") <= bound < 0.016
    large, rig = _campaign(reference, tmp_path / "large", 1188, lambda rng: {
        "sensors.wheel_runout_2": 2 * bound * rng.uniform(1.0, 1.2),
        "sensors.wheel_runout_2_phase_rad": rng.uniform(-np.pi, np.pi)},
        logger=logger, names=None)
    found = _consistent(diagnose(large, reference)).findings[0]
    # named in the wheel channel with its size: a term, or (the counter's noise hides it
    # from the candidate's cost) the relation it breaks
    size = found.parameters.get("wheel_runout_2", found.parameters.get("deviation"))
    assert (found.cause, found.family or found.equation) in {
        ("discovered", "wheel_angle"), ("unexplained", "wheel channel")}, found.evidence
    assert size == pytest.approx(rig.number("sensors.wheel_runout_2"), rel=0.2)


def test_a_discovered_term_never_fits_worse_than_the_model_without_it(reference, tmp_path):
    """A brake gain rising with pressure read through a 64-line encoder with a 50 ms dropout
    per run (the law drawn by the test, unseen by the code under test): the term's fit began
    where the datasheet's gain offset the term's start, stalled at three times the cost of the
    model without it (ΔBIC +3815, so not accepted) and a drift through the runs was named
    instead. The term at zero is that model: its fit can end no worse."""
    _, hidden = HIDDEN["pressure_level"]
    runs, rig = _campaign(reference, tmp_path, 1272, lambda rng: hidden.draw(rng, reference),
                          logger=Logger(encoder_counts=64, dropout_s=0.05), names=None)
    runs = classify_all(runs)
    calibrated = identify(runs, reference, jackknife=False).params
    evidence = Evidence(runs, calibrated, check_campaign(runs, calibrated), [])
    [proposal] = gain_law.FAMILY.propose(evidence)
    scored = score_candidate(proposal.candidate, runs, calibrated, reference,
                             noise_scales(runs, CHANNELS), [])
    assert scored.finding.delta_bic < BIC_THRESHOLD, scored.finding.evidence
    assert scored.finding.parameters[hidden.key] == pytest.approx(rig.number(hidden.slot),
                                                                  rel=hidden.tolerance)
