"""``valve_direction``: a valve that releases at another speed than it applies (issue 60) —
a relay valve whose exhaust is wider than its inlet, as real brake valves' step logs show.

Its law is two terms in A(s)'s generic slot, signed by which port the valve opens (the sign
of ΔP = μ P_static − P: the inlet while the pressure is short of the map, the exhaust
while it is over it, an overshoot included): P̈ = ω_n²·(ΔP + c_s·|ΔP| + c_d·sgn ΔP·Ṗ)
− 2 ζ ω_n Ṗ. Applying, the valve is a second order of ω_a² = ω_n² (1 + c_s) and
2 ζ_a ω_a = 2 ζ ω_n − ω_n² c_d; releasing, the same with −c_s, −c_d. Called for by "valve
follows A(s) between its levels" where the error's regression on these two terms keeps one;
scored beside the valve's generic slot (one rank), so a valve that stiffens with pressure
keeps its own law. Fitted with ω_n, ζ and the map on the actuator runs, held out on the
braking runs' pressure.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import ClassVar

from landing_gear_sim.diagnosis.catalogue import (
    ACTUATOR,
    ACTUATOR_RUNS,
    BRAKE_RUNS,
    PRESSURE,
    STATIC_MAP,
)
from landing_gear_sim.diagnosis.equations.valve import ValveDynamicsLibrary
from landing_gear_sim.diagnosis.families.base import Hidden
from landing_gear_sim.diagnosis.families.equation_terms import TOLERANCE, EquationTerms
from landing_gear_sim.diagnosis.selection import basis_terms
from landing_gear_sim.diagnosis.terms import Listed, factor_term, product_term
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import display

PORT = factor_term(basis.VALVE_ERROR, basis.SIGN)
DIRECTION_TERMS = Listed(tuple(product_term(PORT, factor_term(signal, basis.IDENTITY))
                               for signal in (basis.VALVE_ERROR, basis.PRESSURE_RATE)))
"""The stiffness and the damping, signed by the port the valve opens: sgn ΔP·ΔP (= |ΔP|),
sgn ΔP·Ṗ."""
STIFFNESS, DAMPING = (t.code for t in DIRECTION_TERMS.terms())
MAX_STIFFNESS = 0.95  # |c_s|: one direction's ω_n at least a fifth of the other's


class DirectionLibrary(ValveDynamicsLibrary):
    """A(s)'s error (:class:`ValveDynamicsLibrary`'s) on the two direction terms alone."""

    # a stiffness coefficient of 1 or more leaves one direction no spring: A(s) runs away
    terms = tuple(replace(t, bound=MAX_STIFFNESS) if t.code == STIFFNESS else t
                  for t in basis_terms(DIRECTION_TERMS, "Pa"))

    def law(self, written: str, params: RigParameters) -> str:
        return f"{super().law(written, params)}: {_directions(params)}"


def _directions(params: RigParameters) -> str:
    """Each direction's second order under ``params``' slot, in words."""
    held = {round(params.number(code)): params.number(coeff) for code, coeff in K.VALVE_TERMS}
    stiffness, damping = held.get(STIFFNESS, 0.0), held.get(DAMPING, 0.0)
    wn = 2.0 * math.pi * params.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ)
    zeta = params.number(K.ACTUATOR_DAMPING_RATIO)
    said = []
    for way, sign in (("applies", 1.0), ("releases", -1.0)):
        square = wn * wn * (1.0 + sign * stiffness)
        if square <= 0.0:
            said.append(f"{way} unstably")
            continue
        w = math.sqrt(square)
        ratio = (2.0 * zeta * wn - sign * wn * wn * damping) / (2.0 * w)
        said.append(f"{way} at {display(w / (2.0 * math.pi), 'Hz', '.3g')}, ζ {ratio:.2f}")
    return "; ".join(said)


class ValveDirection(EquationTerms):
    name = "valve_direction"
    reports = "valve_direction"
    words: ClassVar[dict[str, str]] = {
        "valve_direction": "the valve releases at another speed than it applies"}
    library = DirectionLibrary()
    free = (*ACTUATOR, *STATIC_MAP[:3])
    channels = PRESSURE
    runs = ACTUATOR_RUNS
    held_out = BRAKE_RUNS
    # an exhaust 1.6-2.6 times as fast as the inlet (ω_r/ω_a = √((1 − c)/(1 + c)))
    hidden = (Hidden("valve_release", "valve_direction", lambda rng, datasheet: {
        K.VALVE_TERMS[0][0]: float(STIFFNESS),
        K.VALVE_TERMS[0][1]: rng.uniform(-0.75, -0.45)}, K.VALVE_TERMS[0][1], "sgn ΔP·ΔP",
        TOLERANCE),)


FAMILY = ValveDirection()
