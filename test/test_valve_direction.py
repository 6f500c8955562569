"""A valve that releases at another speed than it applies (issue 60's named family, added
as one module and its registry line): named `valve_direction`, its stiffness asymmetry
measured, each direction's second order written out.

The effect is drawn here, from a range the code under test never sees."""

from __future__ import annotations

import re

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.diagnosis.families import REGISTRY
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from msg_tools.io import read_campaign

# the valve's stiffness signed by the port it opens, sgn ΔP·ΔP = |ΔP|: written from the
# model's basis here, not taken from the family under test
BY_PORT = basis.product_code(basis.factor_code(basis.VALVE_ERROR, basis.SIGN),
                             basis.factor_code(basis.VALVE_ERROR, basis.IDENTITY))


def test_the_family_is_registered_once_beside_the_valves_generic_slot():
    ranks = {f.name: f.rank for f in REGISTRY}
    assert ranks["valve_direction"] == ranks["valve_dynamics_equation"]


def test_a_valve_that_releases_faster_than_it_applies_is_named_and_measured(reference,
                                                                             tmp_path):
    rng = np.random.default_rng(6001)
    asymmetry = rng.uniform(-0.8, -0.4)  # the exhaust 1.5-3 times as fast as the inlet
    rig = rig_like(reference, rng).replace({K.VALVE_TERMS[0][0]: float(BY_PORT),
                                            K.VALVE_TERMS[0][1]: asymmetry}, "hidden")
    generate_campaign(tmp_path, rig, 6001)
    result = diagnose(read_campaign(tmp_path).runs, reference)
    assert result.verdict == "discovered", [(f.cause, f.family, f.delta_bic)
                                            for f in result.candidates]
    finding = result.findings[0]
    assert finding.family == "valve_direction" and finding.held_out < 0
    assert finding.parameters["sgn ΔP·ΔP"] == pytest.approx(asymmetry, rel=0.1)
    applies, releases = (float(f) for f in re.findall(r"(?:applies|releases) at ([\d.]+)",
                                                      finding.term))
    truth = np.sqrt((1.0 - asymmetry) / (1.0 + asymmetry))
    assert releases / applies == pytest.approx(truth, rel=0.1), finding.term
