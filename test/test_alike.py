"""Alike explanations are named together (issue 64, item 2): two candidates that both meet
the evidence, neither explaining the campaign twice as well as the other, by ΔBIC or held
out, cannot be told apart by it; one accepted later in its own right is another cause. The
rule on findings, in milliseconds; its wiring into the verdict on two fitted models."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.runs import classify_all
from landing_gear_sim.diagnosis.alike import (
    PREDICTS_BETTER,
    alike_groups,
    cannot_tell_apart,
    rivals,
)
from landing_gear_sim.diagnosis.findings import Finding
from landing_gear_sim.diagnosis.rounds import Round
from landing_gear_sim.diagnosis.scoring import BIC_THRESHOLD, HELD_OUT_THRESHOLD, Scored
from landing_gear_sim.model import keys as K
from landing_gear_sim.report.words import open_sentence
from msg_tools.io import read_campaign


def _finding(cause: str, delta_bic: float | None, held_out: float | None,
             family: str = "") -> Finding:
    return Finding(cause=cause, parameters={}, std={}, evidence="", fit_before={},
                   fit_after={}, delta_bic=delta_bic, held_out=held_out, accepted=True,
                   family=family)


def _scored(finding: Finding) -> SimpleNamespace:
    return SimpleNamespace(finding=finding)


@pytest.fixture
def gains() -> tuple[float, float]:
    """A ΔBIC and a held-out gain that meet the evidence, drawn."""
    rng = np.random.default_rng(64)
    return float(rng.uniform(-5000.0, -50.0)), float(rng.uniform(-3000.0, -30.0))


def test_two_candidates_within_a_factor_of_two_on_both_counts_cannot_be_told_apart(gains):
    bic, held = gains
    first = _finding("actuator_delay", bic, held)
    second = _finding("discovered", 0.8 * bic, 1.5 * held, family="channel_skew")
    assert cannot_tell_apart(first, second) and cannot_tell_apart(second, first)


@pytest.mark.parametrize("which", ["delta_bic", "held_out"])
def test_one_that_explains_twice_as_much_on_either_count_is_told_apart(gains, which):
    bic, held = gains
    first = _finding("actuator_delay", bic, held)
    more = {"delta_bic": bic, "held_out": held}
    more[which] *= 1.05 * PREDICTS_BETTER
    second = _finding("actuator_dynamics", more["delta_bic"], more["held_out"])
    assert not cannot_tell_apart(first, second)


def test_a_candidate_short_of_the_evidence_is_no_rival(gains):
    bic, held = gains
    first = _finding("actuator_delay", bic, held)
    for short in (_finding("drag", 0.9 * BIC_THRESHOLD, held),
                  _finding("drag", bic, 0.9 * HELD_OUT_THRESHOLD),
                  _finding("drag", bic, None)):
        assert not cannot_tell_apart(first, short), short


def test_a_rival_accepted_later_in_its_own_right_is_another_cause_not_a_rival(gains):
    bic, held = gains
    best = _scored(_finding("actuator_delay", bic, held))
    offset = _scored(_finding("pressure_sensor_offset", 0.9 * bic, 0.9 * held))
    dynamics = _scored(_finding("actuator_dynamics", 0.7 * bic, 0.8 * held))
    far = _scored(_finding("drag", 0.1 * bic, 0.1 * held))
    found = rivals(best, [best, offset, dynamics, far],  # type: ignore[list-item]
                   accepted_later=["pressure_sensor_offset"])
    assert found == [dynamics]


def test_a_rounds_rival_stands_beside_the_verdict_with_the_run_that_tells_them_apart(
        reference, tmp_path):
    """The diagnosis's wiring: a round whose adopted delay had a rival alike (a pressure
    channel logged late by as much, drawn here), the rival not accepted later, gives one
    group led by the verdict's finding, with a braking run proposed (wheel-off runs read
    both alike), said in words on the terminal's and the page's first lines."""
    late_s = float(np.random.default_rng(66).uniform(0.003, 0.01))
    bic, held = -2000.0, -900.0
    delay = _finding("actuator_delay", bic, held)
    late = _finding("discovered", 0.7 * bic, 0.8 * held, family="channel_skew")
    short = _finding("drag", 0.2 * bic, 0.2 * held)
    def scored(finding: Finding, changes: dict) -> Scored:
        fit = SimpleNamespace(params=reference.replace(changes, finding.cause),
                              candidate=SimpleNamespace(runs=(), held_out=()))
        return Scored(finding, fit)  # type: ignore[arg-type]
    best = scored(delay, {"elements.actuator_delay": True, K.ACTUATOR_DELAY_S: late_s})
    rival = scored(late, {K.SENSORS_PRESSURE_DELAY_S: late_s})
    rounds = [Round([best, rival, scored(short, {})], best)]
    generate_campaign(tmp_path, rig_like(reference, np.random.default_rng(66)), 66,
                      ["actuator_steps_sweep", "brake_const_30bar"])
    runs = classify_all(read_campaign(tmp_path).runs)
    [group] = alike_groups(rounds, [best], (), runs, lambda _: None)
    assert group.names == ("actuator_delay", "discovered channel_skew")
    assert group.members[0] is delay and group.next_run is not None
    assert group.next_run.settles and group.next_run.closest.channel != "pressure_pa"
    said = open_sentence(SimpleNamespace(alike=[group], next_run=group.next_run))  # type: ignore[arg-type]
    assert said.startswith("actuator_delay: the valve answers later") and " or " in said
    assert "or discovered channel_skew: a channel's samples are stamped out of time" in said
    assert "this campaign cannot tell them apart; the run that would settle it:" in said
    assert group.next_run.command() in said and "drag" not in said
    assert group.to_json()["names"] == ["actuator_delay", "discovered channel_skew"]
