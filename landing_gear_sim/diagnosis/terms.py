"""Term libraries that compose (issue 41), as pysindy's feature libraries do: each library
owns its terms' names, apart from the solver that selects among them.

A term is a basis function of an equation's generic slot (:mod:`landing_gear_sim.model.basis`,
whose code the plant evaluates): :class:`Shaped` puts signals through shapes (``sgn ω``,
``|v|·v``, ``[braked before]``, ``t_c``), ``a + b`` joins two libraries, ``a * b`` takes
every product of a term of one with a term of the other (pysindy's tensored library). An
equation's library is written once from these, over the signals the equation sees
(``calibration.slots.SEES``); the names, units and codes follow from the composition.
"""

from __future__ import annotations

import abc
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

from landing_gear_sim.model import basis_codes as basis
from landing_gear_sim.model.parameters import SPECS, RigParameters
from msg_tools.units import display, signed


@dataclass(frozen=True)
class BasisTerm:
    """One basis function: its code in the plant's slot, its name as a law writes it, and
    its SI unit ('-' when it has none)."""

    code: int
    name: str
    unit: str


_SHAPE_NAMES: dict[int, str] = {
    basis.IDENTITY: "{x}", basis.SIGN: "sgn {x}", basis.SIGNED_SQUARE: "|{x}|·{x}",
    basis.SQUARE: "{x}²", basis.CUBE: "{x}³", basis.STEP: "[{x} > {floor}]",
    basis.DEAD_ZONE: "dz({x}, {floor})", basis.SIGNED_ROOT: "√{x}", basis.COS1: "cos {x}",
    basis.SIN1: "sin {x}", basis.COS2: "cos 2{x}", basis.SIN2: "sin 2{x}",
}
_SHAPE_POWERS: dict[int, float] = {
    basis.IDENTITY: 1, basis.SIGNED_SQUARE: 2, basis.SQUARE: 2, basis.CUBE: 3,
    basis.DEAD_ZONE: 1, basis.SIGNED_ROOT: 0.5}
"""The power of the signal's unit a shape leaves (the others leave none)."""
_NAMED_STEPS: dict[int, str] = {basis.BRAKE_ENERGY: "[braked before]"}
"""Steps with a name of their own (the brake has absorbed more than its floor)."""


def _power(unit: str, power: float) -> str:
    if unit == "-" or power == 0:
        return "-"
    if power == 1:
        return unit
    compound = " " in unit or "/" in unit
    if power == 0.5:
        return f"√({unit})" if compound else f"√{unit}"
    return f"({unit})^{power:g}" if compound else f"{unit}^{power:g}"


def factor_term(signal: int, shape: int) -> BasisTerm:
    """The basis function of one ``signal`` through ``shape``."""
    symbol, unit = basis.SIGNALS[signal]
    floor = display(float(basis.FLOORS[signal]), unit, ".3g")
    name = _NAMED_STEPS.get(signal) if shape == basis.STEP else None
    return BasisTerm(basis.factor_code(signal, shape),
                     name or _SHAPE_NAMES[shape].format(x=symbol, floor=floor),
                     _power(unit, _SHAPE_POWERS.get(shape, 0)))


def product_term(first: BasisTerm, second: BasisTerm) -> BasisTerm:
    """The product of two one-factor terms."""
    units = [u for u in (first.unit, second.unit) if u != "-"]
    return BasisTerm(basis.product_code(first.code, second.code), f"{first.name}·{second.name}",
                     " ".join(units) or "-")


def term_of(code: int) -> BasisTerm:
    """The basis function of ``code`` (its name and unit from its factors)."""
    parts = [factor_term(f // basis.FACTOR, f % basis.FACTOR) for f in basis.factors(code)]
    return parts[0] if len(parts) == 1 else product_term(*parts)


def coefficient_unit(equation_unit: str, term: BasisTerm) -> str:
    """The unit of a coefficient of ``term`` in an equation of ``equation_unit``."""
    if term.unit == "-":
        return equation_unit
    if term.unit in (f"√{equation_unit}", f"√({equation_unit})"):  # √P in Pa: √Pa
        return term.unit
    base, _, power = term.unit.partition("^")
    if base == equation_unit and power:  # |ΔP|·ΔP in an equation in Pa: 1/Pa
        left = 1.0 - float(power)
        return _power(base, left) if left > 0 else f"1/{_power(base, -left)}"
    factors = term.unit.split(" ")
    if equation_unit in factors:  # P·ΔP in an equation in Pa: 1/Pa, not Pa/(Pa Pa)
        factors.remove(equation_unit)
        rest = " ".join(factors)
        if not rest:  # sgn Ṗ·ΔP in an equation in Pa: a plain number
            return "-"
        if "/" in rest and not any(c in rest for c in " (√"):  # m/s: s/m
            numerator, denominator = rest.split("/")
            return f"{denominator}/{numerator}"
        return f"1/{rest}" if " " not in rest else f"1/({rest})"
    whole = term.unit.startswith("√") and " " not in term.unit  # a root reads as one
    per = f"({term.unit})" if not whole and (" " in term.unit or "/" in term.unit) \
        else term.unit
    return f"{equation_unit}/{per}" if equation_unit != "-" else f"1/{per}"


def slot_notes(params: RigParameters) -> dict[str, str]:
    """By key, what each filled place of every generic slot of ``params`` holds: the basis
    function its code names, and its coefficient's unit, its equation's per φ as the schema
    gives it (a params file says what '37.0' means; this reads no equation's library, so
    ``params`` starts at once)."""
    notes: dict[str, str] = {}
    for spec in SPECS:
        if not spec.key.endswith("_coeff") or params.number(spec.key) == 0.0:
            continue
        code = spec.key.removesuffix("_coeff") + "_code"
        term = term_of(round(params.number(code)))
        notes[code] = term.name
        notes[spec.key] = coefficient_unit(spec.unit.removesuffix(" per phi"), term)
    return notes


def written_term(value: float, term: BasisTerm, equation_unit: str) -> str:
    """One term of a law: '− 150 N m·[braked before]'."""
    unit = coefficient_unit(equation_unit, term)
    return f"{signed(value, '' if unit == '-' else unit)}·{term.name}"


class TermLibrary(abc.ABC):
    """A set of basis functions, composable: ``+`` joins, ``*`` takes products."""

    @abc.abstractmethod
    def terms(self) -> tuple[BasisTerm, ...]:
        """The library's basis functions, in a fixed order, each once."""

    def __add__(self, other: TermLibrary) -> TermLibrary:
        return Joined((self, other))

    def __mul__(self, other: TermLibrary) -> TermLibrary:
        return Tensored(self, other)

    def __len__(self) -> int:
        return len(self.terms())


@dataclass(frozen=True)
class Shaped(TermLibrary):
    """Every one of ``signals`` through every one of ``shapes`` (``model.basis`` indices)."""

    signals: Sequence[int]
    shapes: Sequence[int]

    def terms(self) -> tuple[BasisTerm, ...]:
        return tuple(factor_term(s, f) for s in self.signals for f in self.shapes)


@dataclass(frozen=True)
class Joined(TermLibrary):
    """The terms of each library, the first occurrence of each code kept."""

    parts: Sequence[TermLibrary]

    def terms(self) -> tuple[BasisTerm, ...]:
        seen: dict[int, BasisTerm] = {}
        for term in itertools.chain.from_iterable(p.terms() for p in self.parts):
            seen.setdefault(term.code, term)
        return tuple(seen.values())


@dataclass(frozen=True)
class Tensored(TermLibrary):
    """Every product of a term of ``first`` with a term of ``second`` of another signal (a
    signal times itself is a shape's business)."""

    first: TermLibrary
    second: TermLibrary

    def terms(self) -> tuple[BasisTerm, ...]:
        return tuple(product_term(a, b) for a in self.first.terms()
                     for b in self.second.terms()
                     if a.code // basis.FACTOR != b.code // basis.FACTOR)


@dataclass(frozen=True)
class Listed(TermLibrary):
    """Basis functions as a law names them, a signal's product with itself included
    (sgn ΔP·ΔP: a valve's stiffness by the port it opens)."""

    listed: Sequence[BasisTerm]

    def terms(self) -> tuple[BasisTerm, ...]:
        return tuple(self.listed)


@dataclass(frozen=True)
class Without(TermLibrary):
    """``library`` less the terms whose codes the equation's own parameters already own
    (k_b P in the wheel's balance, k_L v² in the loading device's)."""

    library: TermLibrary
    owned: frozenset[int]

    def terms(self) -> tuple[BasisTerm, ...]:
        return tuple(t for t in self.library.terms() if t.code not in self.owned)
