"""The rig's equations' generic slots (issue 29): the plant carries them, the calibration
reads around them, each equation's error finds its own term, and the diagnosis reports a
term no named family holds as `discovered` in its equation, with its law and its value.

The effects are drawn here, from ranges the code under test never sees."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.measured import Simulations
from landing_gear_sim.calibration.runs import classify_all
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.diagnosis.equations import Equation
from landing_gear_sim.diagnosis.equations import registry as eq
from landing_gear_sim.diagnosis.equations.flywheel import flywheel_carries
from landing_gear_sim.diagnosis.families import HIDDEN, REGISTRY
from landing_gear_sim.diagnosis.families.equation_terms import EquationTerms
from landing_gear_sim.diagnosis.library import Campaign
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from msg_tools.io import read_campaign

RUNS = ("actuator_ramp", "brake_const_10bar", "brake_const_20bar", "brake_const_30bar",
        "brake_osc_low", "brake_osc_high")
EQUATION_CASES = sorted(h.name for f in REGISTRY if isinstance(f, EquationTerms) and f.generic
                        for h in f.hidden)


def _campaign(reference, folder, seed: int, hidden: dict[str, float] | None = None,
              runs: tuple[str, ...] = RUNS):
    """A generated campaign (the project's own rig generator) with ``hidden`` in its rig,
    classified, and the model calibrated on it."""
    rig = rig_like(reference, np.random.default_rng(seed))
    if hidden:
        rig = rig.replace(hidden, "hidden")
    generate_campaign(folder, rig, seed, runs)
    runs = classify_all(read_campaign(folder).runs)
    return runs, identify(runs, reference, jackknife=False).params


def test_bearing_losses_slow_the_rig_and_the_energy_books_them_as_drag(reference):
    bearings = reference.replace({K.WHEEL_EXTRA_TORQUE_N_M: 80.0,
                                  K.WHEEL_EXTRA_TORQUE_N_M_S_PER_RAD: 0.4,
                                  K.FLYWHEEL_EXTRA_FORCE_N: 300.0,
                                  K.FLYWHEEL_EXTRA_FORCE_N_S_PER_M: 4.0}, "bearings")
    plain = simulate(reference, sc.constant_pressure_test(reference, 30e5))
    slowed = simulate(bearings, sc.constant_pressure_test(bearings, 30e5))
    mass = 3500.0
    lost = 0.5 * mass * (slowed.speed_m_s[0] ** 2 - slowed.speed_m_s[-1] ** 2)
    spent = (slowed.brake_energy_j[-1] + slowed.drag_energy_j[-1] + slowed.slip_energy_j[-1]
             + slowed.damping_energy_j[-1] + 0.75 * (slowed.wheel_speed_rad_s[-1] ** 2
                                                     - slowed.wheel_speed_rad_s[0] ** 2)
             + 0.5 * 272.9 * slowed.gear_rate_rad_s[-1] ** 2
             + 0.5 * 6.9e5 * slowed.gear_angle_rad[-1] ** 2)
    assert abs(lost - spent) < 1e-4 * lost
    assert slowed.time_s[-1] < plain.time_s[-1]
    assert slowed.drag_energy_j[-1] > plain.drag_energy_j[-1] + 300.0 * 100.0


def test_a_load_sag_in_speed_takes_load_off_where_the_rig_runs_fast(reference):
    sag = reference.replace({K.LOADING_EXTRA_LOAD_N_S_PER_M: 50.0}, "sag")
    plain = simulate(reference, sc.constant_pressure_test(reference, 30e5))
    sagging = simulate(sag, sc.constant_pressure_test(sag, 30e5))
    early = np.flatnonzero((plain.time_s > 1.0) & (plain.time_s < 1.5))
    drop = plain.vertical_load_n[early] - sagging.vertical_load_n[early]
    assert drop == pytest.approx(50.0 * plain.speed_m_s[early], rel=0.02)


def test_a_known_bearing_torque_is_not_read_as_brake_gain(reference, tmp_path):
    """The torque balance gives the brake's torque beside the model's bearing torque: with
    the slot known, k_b comes out as the rig's; without it, it absorbs the torque."""
    torque = float(np.random.default_rng(7).uniform(60.0, 120.0))
    runs, calibrated = _campaign(reference, tmp_path, 301, {K.WHEEL_EXTRA_TORQUE_N_M: torque})
    rig = rig_like(reference, np.random.default_rng(301))
    braking = [br.prepare(r, calibrated) for r in runs if r.braking]
    known = calibrated.replace({K.WHEEL_EXTRA_TORQUE_N_M: torque}, "known")
    (with_slot,) = br.fit_brake_gain(braking, known)
    (without,) = br.fit_brake_gain(braking, calibrated.replace(
        {K.WHEEL_EXTRA_TORQUE_N_M: 0.0}, "unknown"))
    truth = rig.number(K.BRAKE_GAIN_N_M_PER_PA)
    assert with_slot.value == pytest.approx(truth, rel=0.005)
    assert abs(without.value / truth - 1) > 2 * abs(with_slot.value / truth - 1)


@pytest.mark.parametrize("case", EQUATION_CASES)
@pytest.mark.filterwarnings("error::RuntimeWarning")  # a trial step the valve did not survive
def test_each_equation_finds_its_own_hidden_term_and_no_other(reference, tmp_path, case):
    family, hidden = HIDDEN[case]
    drawn = hidden.draw(np.random.default_rng(sum(map(ord, case))), reference)
    dynamic = ("actuator_steps_sweep",) if family.library is eq.VALVE_DYNAMICS else ()
    runs, calibrated = _campaign(reference, tmp_path, 310, drawn, RUNS + dynamic)
    campaign = Campaign(runs, [br.prepare(r, calibrated) for r in runs if r.braking])
    found = {library.relation: {s.term.name: s.value
                                for s in library.select(campaign, calibrated)}
             for library in eq.LIBRARIES}
    assert found.pop(family.library.relation) == pytest.approx(
        {hidden.key: drawn[hidden.slot]}, rel=hidden.tolerance)
    # a channel's term is read wherever the channel is: by the wheel's torque balance and the
    # valve (the pressure), the flywheel (F_x)
    if family.library.equation not in (Equation.FX_CHANNEL, Equation.PRESSURE_CHANNEL):
        assert not any(found.values()), found


def test_a_clean_campaign_violates_no_equation_and_says_so(reference, tmp_path):
    from landing_gear_sim.diagnosis.consistency import check_campaign

    runs, calibrated = _campaign(reference, tmp_path, 320)
    checks = [c for c in check_campaign(runs, calibrated)
              if c.relation in (Relation.VALVE_MAP, Relation.WHEEL_BALANCE, Relation.TYRE_LAW,
                                Relation.FLYWHEEL_BALANCE, Relation.LOADING_LAW)]
    assert len(checks) == 5
    assert not [c.describe() for c in checks if c.violated]


def test_a_known_map_bend_is_read_around_by_the_static_map_fit(reference, tmp_path):
    """The quasi-static ramp's fit of k1, k2 beside the model's k3: with the bend known, k1
    comes out as the rig's; without it, the quadratic absorbs the bend."""
    from landing_gear_sim.calibration.actuator import fit_static_map

    bend = float(np.random.default_rng(9).uniform(-4e6, -2e6))
    runs, calibrated = _campaign(reference, tmp_path, 302, {K.ACTUATOR_EXTRA_MAP_PA_PER_A3: bend})
    ramps = [r for r in runs if r.kind == "actuator_ramp"]
    truth = rig_like(reference, np.random.default_rng(302)).number(K.ACTUATOR_MAP_K1_PA_PER_A)
    k1 = {known: {e.key: e.value for e in fit_static_map(ramps, calibrated.replace(
        {K.ACTUATOR_EXTRA_MAP_PA_PER_A3: bend if known else 0.0}, "map"))}[
        K.ACTUATOR_MAP_K1_PA_PER_A] for known in (True, False)}
    assert k1[True] == pytest.approx(truth, rel=0.01)
    assert abs(k1[False] / truth - 1) > 3 * abs(k1[True] / truth - 1)


def test_a_bent_map_still_gives_the_current_for_a_pressure(reference):
    """A stop at constant pressure needs the map's inverse, the cubic term included."""
    bent = reference.replace({K.ACTUATOR_EXTRA_MAP_PA_PER_A3: -3e6}, "bent")
    for pressure in (5e5, 20e5, 40e5):
        current = sc.current_for_pressure(bent, pressure)
        assert el.valve_static_pressure(bent.vector(), current) == pytest.approx(pressure,
                                                                                 rel=1e-6)
    assert sc.current_for_pressure(bent, 40e5) > sc.current_for_pressure(reference, 40e5)


def test_a_bearing_torque_the_model_holds_leaves_free_rolling_holding(reference, tmp_path):
    """The tyre pushes a bearing's torque before the brake acts: with the slot known the
    free-rolling relation holds; without it, it is violated."""
    from landing_gear_sim.diagnosis.consistency import check_campaign
    from landing_gear_sim.diagnosis.relations import Relation

    torque = float(np.random.default_rng(11).uniform(60.0, 120.0))
    runs, calibrated = _campaign(reference, tmp_path, 303, {K.WHEEL_EXTRA_TORQUE_N_M: torque})
    for known, broken in ((0.0, True), (torque, False)):
        model = calibrated.replace({K.WHEEL_EXTRA_TORQUE_N_M: known}, "bearing")
        checks = [c for c in check_campaign(runs, model) if c.relation == Relation.FREE_ROLLING]
        assert checks and any(c.violated for c in checks) == broken, [
            c.describe() for c in checks]


def test_a_later_family_is_tried_when_the_accepted_term_leaves_its_relation_violated(
        reference, monkeypatch):
    """A brake gain law (rank 6) once took a bearing's torque and left free rolling
    violated; the wheel's equation (rank 8) must still be tried and, explaining more, win.
    When the accepted term leaves nothing of it, the search stops there."""
    from landing_gear_sim.diagnosis import discovered as d
    from landing_gear_sim.diagnosis.families.base import Family, Proposal

    tried: list[str] = []

    class Stand(Family):
        def __init__(self, name: str, rank: int, relation: Relation) -> None:
            self.name, self.rank, self.relations = name, rank, (relation,)

        def propose(self, evidence):
            tried.append(self.name)
            return [Proposal(candidate=None)]  # type: ignore[arg-type]

        def formula(self, candidate, params):
            return ""

    law, bearing = Stand("law", 6, Relation.GAIN_IN_PRESSURE), Stand("wheel", 8,
                                                                     Relation.FREE_ROLLING)
    accepted = type("Accepted", (), {"finding": type("F", (), {
        "accepted": True, "cause": "discovered", "family": "", "delta_bic": None,
        "held_out": None})()})
    scored = {"law": accepted(), "wheel": accepted()}
    monkeypatch.setattr(d, "REGISTRY", (law, bearing))
    monkeypatch.setattr(d, "_score_discovered", lambda family, *_: scored[family.name])
    monkeypatch.setattr(d, "_better", lambda first, second, violated: second)
    monkeypatch.setattr(d, "_called_for", lambda family, s, evidence: s)
    for left, found, names in (({Relation.FREE_ROLLING}, "wheel", ["law", "wheel"]),
                               (set(), "law", ["law"])):
        tried.clear()
        monkeypatch.setattr(d, "_violated_under", lambda s, runs, left=left: [
            type("Violated", (), {"relation": r})() for r in left])
        assert d.discovered([], reference, reference, {}, [], [], print).scored \
            is scored[found]
        assert tried == names


def test_a_held_out_gain_on_other_runs_and_channels_does_not_outweigh_the_relations():
    """A pressure transducer's drift through a 256-count encoder: the channel's term gained
    1054 on the pressure of three runs and left two relations violated, a wheel term gained
    7074 on the wheel speed of three others and left three; the wheel term had won on its
    6.7 times larger gain. Gains measured alike still decide."""
    from landing_gear_sim.diagnosis import discovered as d

    def scored(gain: float, runs: tuple[str, ...], channels: tuple[str, ...]):
        finding = type("F", (), {"accepted": True, "held_out": -gain, "checked_on": runs,
                                 "delta_bic": -100.0})()
        candidate = type("C", (), {"channels": channels})()
        return type("S", (), {"finding": finding, "fit": type("Fit", (), {
            "candidate": candidate})()})()

    channel = scored(1054.0, ("a", "b", "c"), ("pressure_pa", "wheel_speed_rad_s"))
    wheel = scored(7074.0, ("d", "e", "f"), ("wheel_speed_rad_s",))
    left = {id(channel): [1, 2], id(wheel): [1, 2, 3]}
    violated = lambda s: left[id(s)]  # noqa: E731
    assert d._better(channel, wheel, violated) is channel
    alike = scored(7074.0, ("a", "b", "c"), ("pressure_pa", "wheel_speed_rad_s"))
    left[id(alike)] = [1, 2, 3]
    assert d._better(channel, alike, violated) is alike


def test_the_flywheel_tells_a_load_cell_crosstalk_from_a_bearing_torque(reference, tmp_path):
    """Both make the F_x channel read a force in free rolling; only the crosstalk is a force
    the flywheel does not feel."""
    fraction = float(np.random.default_rng(8).uniform(0.01, 0.03))
    for hidden, carried in (({K.SENSORS_CROSSTALK_FX_PER_FZ: fraction}, fraction),
                            ({K.WHEEL_EXTRA_TORQUE_N_M: 80.0}, 0.0)):
        folder = tmp_path / str(carried)
        runs, calibrated = _campaign(reference, folder, 330, hidden)
        braking = [br.prepare(r, calibrated) for r in runs if r.braking]
        found, _ = flywheel_carries(braking, calibrated, lambda b: b.run.vertical_load_n)
        assert found == pytest.approx(carried, abs=0.1 * fraction)


def test_an_effect_no_family_names_is_discovered_in_its_equation(reference, tmp_path):
    """Case and size drawn by the test among the equations' hidden effects: `discovered`
    with the equation as its family, a held-out gain, no catalogue name, the law written
    out and the value within the case's tolerance."""
    rng = np.random.default_rng(340)
    family, hidden = HIDDEN[str(rng.choice(EQUATION_CASES))]
    rig = rig_like(reference, rng).replace(hidden.draw(rng, reference), "hidden")
    generate_campaign(tmp_path, rig, 340, RUNS)
    result = diagnose(read_campaign(tmp_path).runs, reference)
    assert result.verdict == "discovered", [(f.cause, f.family, f.delta_bic, f.held_out)
                                            for f in result.candidates]
    finding = result.findings[0]
    assert finding.family == hidden.family and finding.held_out < 0
    assert not {f.cause for f in result.findings} - {"discovered", "unexplained"}
    assert finding.term.startswith(family.library.law("", rig).split("=")[0])
    truth = rig.number(hidden.slot)
    assert finding.parameters[hidden.key] == pytest.approx(truth, rel=hidden.tolerance)


def test_a_valve_map_that_bends_is_discovered_in_the_valve_not_named_a_valve_effect(
        reference, tmp_path):
    """The static map bends beyond the quadratic the calibration fits (the test draws the
    bend): fitted on the quasi-static ramp, the family must win on the braking runs' pressure,
    and no catalogued valve effect (delay, offset) may take its place."""
    rng = np.random.default_rng(350)
    bend = float(rng.uniform(-3.5e6, -1.5e6))
    rig = rig_like(reference, rng).replace({K.ACTUATOR_EXTRA_MAP_PA_PER_A3: bend}, "bent")
    generate_campaign(tmp_path, rig, 350, RUNS)
    result = diagnose(read_campaign(tmp_path).runs, reference)
    assert [f.cause for f in result.findings] == ["discovered"], result.findings
    finding = result.findings[0]
    assert finding.family == "valve" and finding.held_out < 0
    assert finding.term.startswith("P_static = ") and "e³" in finding.term
    assert finding.parameters["e³"] == pytest.approx(bend, rel=0.1)


def test_of_two_causes_beside_a_discovered_term_only_the_one_it_replaces_goes(reference,
                                                                               monkeypatch):
    """Each cause is scored again from the extended model without it (here: told by a stand-
    in); the one that no longer earns its place goes, its element off in the final model,
    and the other stays."""
    from landing_gear_sim.diagnosis.catalogue import CATALOGUE, CandidateFit
    from landing_gear_sim.diagnosis.discovered import Discovery, Story
    from landing_gear_sim.diagnosis.findings import Finding
    from landing_gear_sim.diagnosis.scoring import Scored

    def scored(cause: str, params) -> Scored:
        finding = Finding(cause=cause, parameters={}, std={}, evidence="", fit_before={},
                          fit_after={}, delta_bic=-50.0, held_out=-50.0, accepted=True,
                          term=f"law of {cause}")
        return Scored(finding, CandidateFit(CATALOGUE.get(cause) or CATALOGUE["drag"], params,
                                            {}, {}, np.ones(3)))

    extended = reference.replace({"elements.tire_relaxation": True,
                                  "tyre.relaxation_length_m": 0.1,
                                  "elements.actuator_delay": True,
                                  "actuator.delay_s": 0.005}, "both causes")
    causes = [scored("tire_relaxation", extended), scored("actuator_delay", extended)]
    said: list[str] = []
    story = Story([], reference, reference, {}, [], [], said.append, Simulations([]))
    monkeypatch.setattr(Story, "_earns", lambda self, cause, model: cause is causes[1])
    extension = story._beside([], causes, Discovery(scored("discovered", extended)),
                              Discovery(None))
    assert extension.kept == [causes[1]] and said == [
        "tire_relaxation not needed beside law of discovered"]
    final = extension.scored.fit.params
    assert not final.has("tire_relaxation") and final.has("actuator_delay")
