"""The run that would settle it (issue 64, item 3): each explanation simulated on the runs
the rig can make, the run whose predictions differ most against the campaign's logger
noise proposed, and ``campaign --profile`` writes it."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.runs import RunKind, Setup, classify_all
from landing_gear_sim.cli import main
from landing_gear_sim.diagnosis.next_run import (
    PROPOSED,
    SETTLES,
    Explanation,
    _closest,
    _noise,
    _template,
    next_run,
)
from landing_gear_sim.model import keys as K
from msg_tools.io import read_campaign, read_run


@pytest.fixture(scope="module")
def campaign(reference, tmp_path_factory):
    """A step-and-sweep run and a 30 bar stop, as the generator logs them."""
    folder = tmp_path_factory.mktemp("campaign")
    generate_campaign(folder, rig_like(reference, np.random.default_rng(64)), 64,
                      ["actuator_steps_sweep", "brake_const_30bar"])
    return classify_all(read_campaign(folder).runs)


@pytest.fixture(scope="module")
def late_or_delayed(reference):
    """A valve that answers late, and a pressure channel logged as late, by one size drawn
    here (3-10 ms): alike in the pressure, apart in the wheel's balance."""
    late_s = float(np.random.default_rng(65).uniform(0.003, 0.01))
    delayed = reference.replace({"elements.actuator_delay": True, K.ACTUATOR_DELAY_S: late_s},
                                "the valve answers late")
    logged_late = reference.replace({K.SENSORS_PRESSURE_DELAY_S: late_s},
                                    "the pressure channel logs late")
    return [Explanation("actuator_delay", delayed), Explanation("late channel", logged_late)]


def test_a_late_channel_and_a_late_valve_are_told_apart_only_by_a_braking_run(
        campaign, late_or_delayed):
    """With the wheel off the flywheel both read the same pressure: only a run that brakes
    shows the torque following the valve's pressure, not the channel's."""
    noise = _noise(campaign)
    for proposal in PROPOSED:
        template = _template(proposal.spec, late_or_delayed[0].params, campaign[0].rate_hz)
        assert template is not None
        apart = _closest(late_or_delayed, template, noise)
        assert apart is not None
        if template.kind.setup is Setup.ACTUATOR:
            assert apart.evidence < SETTLES, (proposal.words, apart)
    found = next_run(late_or_delayed, campaign)
    assert found is not None and found.settles
    assert found.proposal.spec.profile in ("constant", "osc-low", "osc-high", "steps")
    assert found.closest.channel != "pressure_pa"
    assert found.equation in ("tyre", "wheel", "flywheel"), found.sentence()


def test_a_valve_log_is_proposed_only_runs_with_the_wheel_off(campaign, late_or_delayed,
                                                               reference):
    valve_only = [r for r in campaign if not r.braking]
    none_ = Explanation("none", reference)
    found = next_run([none_, late_or_delayed[0]], valve_only)
    assert found is not None and found.settles, found
    assert found.proposal.spec.profile in ("steps", "sweep", "ramp")
    assert found.closest.channel == "pressure_pa" and found.equation == "valve"
    # a late channel alone changes no pressure a wheel-off run reads differently from a
    # late valve: the two cannot be told apart without a wheel
    apart = next_run(late_or_delayed, valve_only)
    assert apart is not None and not apart.settles
    assert "no run the rig can make tells them apart" in apart.sentence()


def test_an_explanations_candidate_is_proposed_only_runs_it_reads(campaign, reference):
    """A tyre's relaxation is fitted on constant-pressure stops: an oscillating stop would
    show it, and leave the diagnosis as it was."""
    relaxing = reference.replace({"elements.tire_relaxation": True,
                                  K.TYRE_RELAXATION_LENGTH_M: 0.5}, "a relaxing tyre")
    found = next_run([Explanation("none", reference),
                      Explanation("tire_relaxation", relaxing, (RunKind.BRAKE_CONSTANT,))],
                     campaign)
    assert found is not None and found.proposal.spec.profile == "constant", found
    assert found.closest.evidence >= SETTLES


def test_campaign_profile_writes_the_proposed_run_alone(tmp_path, capsys):
    folder = tmp_path / "next_run"
    assert main(["campaign", str(folder), "--profile", "steps", "--rig", "--seed", "3"]) == 0
    [path] = sorted(folder.glob("*.csv"))
    assert path.name == "next_steps.csv"  # beside a campaign's own steps run
    run = classify_all([read_run(path)])[0]
    assert run.braking and run.kind is RunKind.BRAKE_OSCILLATING, run.kind
    assert main(["campaign", str(tmp_path / "x"), "--profile", "steps", "--shuffled"]) == 2
    assert "--profile writes one run" in capsys.readouterr().err
