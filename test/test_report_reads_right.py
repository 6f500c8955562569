"""The diagnosis page (issue 42): each check beside the one that measures the same, and a
reason for every candidate's yes or no."""

from __future__ import annotations

from landing_gear_sim.diagnosis.relations import Check, Relation
from landing_gear_sim.report.diagnosis import paired_checks


def _check(relation: Relation, phase: str, deviation: float, run: str = "actuator_ramp"
           ) -> Check:
    return Check(relation, run, phase, deviation, 0.7, 150.0, "N")


def test_a_relation_checked_on_two_channels_of_a_run_pairs_each_channel_with_itself():
    """'no contact ⇒ no load' on F_x and on F_z of one run: the page had put the calibrated
    model's F_x (−0.2765 N) beside the extended model's F_z (−0.6046 N)."""
    calibrated = [_check(Relation.NO_CONTACT, "whole run, F_x", -0.2765),
                  _check(Relation.NO_CONTACT, "whole run, F_z", -0.6046)]
    extended = [_check(Relation.NO_CONTACT, "whole run, F_x", -0.2801),
                _check(Relation.NO_CONTACT, "whole run, F_z", -0.6046)]
    pairs = paired_checks(calibrated, extended)
    assert [(b.phase, a.phase) for b, a in pairs if b] == [
        ("whole run, F_x", "whole run, F_x"), ("whole run, F_z", "whole run, F_z")]
    assert [b.deviation for b, _ in pairs if b] == [-0.2765, -0.6046]


def test_an_equations_check_pairs_across_the_terms_each_model_kept():
    """An equation's check names the terms its fit kept, which differ between the models:
    the one check of that relation is still its pair; a check made under one model only has
    none."""
    calibrated = [_check(Relation.WHEEL_BALANCE, "braking runs, sgn ω", 12.0, "campaign")]
    extended = [_check(Relation.WHEEL_BALANCE, "braking runs, |ω|·ω", 0.3, "campaign"),
                _check(Relation.LOADING_LAW, "braking runs, v", 2.0, "campaign")]
    (wheel, loading) = paired_checks(calibrated, extended)
    assert wheel[0] is calibrated[0] and loading[0] is None


def test_every_candidate_says_why_it_was_or_was_not_accepted():
    """The rule the page states is ΔBIC and a held-out gain; a candidate that met both was
    marked 'no' with no reason (its gain on the channel it helps was 0.04 fit-% points)."""
    from landing_gear_sim.diagnosis.scoring import HeldOut, _rejection

    held = HeldOut(delta=-16.0, gain=0.04)
    assert "0.04 fit-% points" in _rejection(-97.0, held, False, "")
    assert "ΔBIC +3" in _rejection(3.0, held, False, "")
    assert "no held-out run" in _rejection(-97.0, HeldOut(), False, "")
    assert "edge of its range" in _rejection(-97.0, HeldOut(delta=-50.0, gain=2.0), True, "")
    assert _rejection(-97.0, HeldOut(delta=-50.0, gain=2.0), False, "") == ""


def test_the_consistency_chart_colours_only_what_the_verdict_calls_violated(tmp_path):
    """'vertical load follows F_z0 − k_L v²' drawn orange at 13σ past the 6σ line beside a
    verdict of 0 violated (its deviation was under the physical floor). Each bar is now its
    deviation over max(6σ, floor): past 1 exactly when violated, and only then red."""
    from landing_gear_sim.report.diagnosis import _colour, reach

    under_floor = Check(Relation.LOADING_LAW, "campaign", "settled", 130.0, 10.0, 150.0, "N")
    violated = Check(Relation.LOADING_LAW, "campaign", "settled", 300.0, 10.0, 150.0, "N")
    within_sigma = Check(Relation.LOADING_LAW, "campaign", "settled", 50.0, 10.0, 1.0, "N")
    assert under_floor.z > 6 and not under_floor.violated
    for check in (under_floor, violated, within_sigma):
        assert (reach(check) > 1.0) == check.violated
        assert (_colour(check) == "tab:red") == check.violated
