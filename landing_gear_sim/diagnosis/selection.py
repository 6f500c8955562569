"""Selecting an equation's terms from its library (issue 41): a sparse solver, then proof.

An equation's error (:class:`Rows`, per run) is regressed on its library's terms beside the
terms whose coefficients the calibration owns, by a sparse solver (scikit-learn's LARS
lasso, BIC). Of terms the samples cannot tell apart only the first is regressed on (the
others are its alternatives, :attr:`Selected.alike`); of the terms the lasso keeps, at most
:data:`MAX_KEPT`, the weakest is dropped while an ordinary fit of the kept and owned terms
does not find it against the error's own noise (t over the error's effective count, above
:data:`Z_VIOLATED`); what is left is judged jointly (:class:`Fitted`): significant when its
Δχ² and its rms effect clear :data:`Z_VIOLATED` and the equation's floor (:data:`MIN_EFFECT`
of its scale, or :data:`NOISE_FLOOR` times what the regressors' own noise makes of it).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import numpy as np

from landing_gear_sim.calibration.statistics import effective_count
from landing_gear_sim.diagnosis.relations import Z_VIOLATED
from landing_gear_sim.diagnosis.sparse import sparse_coefficients
from landing_gear_sim.diagnosis.terms import TermLibrary, coefficient_unit
from landing_gear_sim.model import basis
from landing_gear_sim.model.parameters import RigParameters

MIN_EFFECT = 0.005  # a term's rms effect over the equation's scale: half a per cent
MAX_KEPT = basis.SLOT_TERMS  # terms a slot holds
SPANNED = 1e-3  # a column this close to the span of those before it adds nothing
ALIKE = 0.05  # a column this close to one before it alone is that one, as the samples see
# times the error the regressors' own noise makes: nulls read up to 0.87 of it (the tyre
# through a 256-count encoder, at 25-29σ); at 3 a tyre's μ_B·v² logged at 200 Hz (1.3-1.8)
# came out `none`
NOISE_FLOOR = 1.5

S = TypeVar("S")  # what a library reads one run's rows from: a braking run's signals, ...


@dataclass(frozen=True)
class Term(Generic[S]):
    """A term of an equation's slot: its key (the coefficient; '' for a basis function of
    the equation's generic slot, which takes a free place of the slot when proposed), how it
    is written in the law (``symbol``, '' for a constant), the coefficient's SI unit and
    admissible magnitude, and its variable as the term enters the equation's error
    (coefficient 1): from what the library reads a run from and the model (``values``), or
    the basis function ``code`` of ``model.basis`` at the equation's measured signals."""

    key: str
    symbol: str
    unit: str
    bound: float
    values: Callable[[S, RigParameters], np.ndarray] | None = None
    code: int | None = None

    @property
    def name(self) -> str:
        """The contract name of its coefficient."""
        return self.key.split(".")[1] if self.key else self.symbol.lstrip("·")


def basis_terms(library: TermLibrary, equation_unit: str) -> tuple[Term[Any], ...]:
    """The terms of a composed ``library`` (:mod:`~.terms`) in an equation of
    ``equation_unit``; their bounds are set when a fit proposes them."""
    return tuple(Term("", f"·{t.name}", coefficient_unit(equation_unit, t), math.inf,
                      code=t.code) for t in library.terms())


def variable(term: Term[S], source: S, params: RigParameters) -> np.ndarray:
    """A term's variable over a whole run (a term with its own ``values``)."""
    if term.values is None:
        raise ValueError(f"term {term.symbol} is a basis function: read it at the signals")
    return term.values(source, params)


def term_columns(terms: Sequence[Term[S]], source: S, params: RigParameters, index: np.ndarray,
             measured: np.ndarray | None) -> np.ndarray:
    """The terms' variables at the samples ``index`` (m, k); ``measured``: the equation's
    signals there (``calibration.slots``), for the basis functions."""
    columns = []
    for term in terms:
        if term.code is not None and measured is not None:
            columns.append(basis.term_values(term.code, measured))
        else:
            columns.append(variable(term, source, params)[index])
    return np.column_stack(columns)


@dataclass(frozen=True)
class Rows:
    """One run's regression rows: the equation's error, its library's terms (m, k), the
    terms the calibration owns (m, j), and the equation's scale [its unit]."""

    error: np.ndarray
    terms: np.ndarray
    owned: np.ndarray
    scale: float
    noise: float = 0.0  # what the regressors' own noise alone makes of the error (rms)
    # what the noise in the inputs the model is fed makes of the error (rms): a null's
    # deviation as large as a real effect's, which only the scoring tells apart
    input_noise: float = 0.0


@dataclass(frozen=True)
class Selected:
    """A term the equation's error needs: its fitted value, its t and its rms effect."""

    term: Term
    value: float
    t: float
    effect: float
    alike: tuple[Term, ...] = ()  # terms the samples cannot tell from it (scaled alike)


@dataclass(frozen=True)
class Fitted:
    """What a library's terms explain of an equation's error: the terms kept (each with its
    own fit beside the others and the owned terms), their joint rms effect, and their joint
    z: √(Δχ²) of the error's fit with and without them, over the error's effective count
    (for one term, its t). Judged jointly: terms that nearly repeat each other share out
    one effect in large opposite coefficients."""

    selected: list[Selected]
    effect: float
    z: float


def fit_terms(terms: Sequence[Term[Any]], rows: Sequence[Rows]) -> Fitted | None:
    """The terms the lasso keeps among ``terms`` and the owned ones — of terms the samples
    cannot tell apart, the first; at most MAX_KEPT, the weakest dropped while it is not
    significant — each with its ordinary fit beside the owned terms (the strongest single
    term when the lasso keeps none: the relation is checked all the same)."""
    y = np.concatenate([r.error for r in rows])
    x, owned = np.vstack([r.terms for r in rows]), np.vstack([r.owned for r in rows])
    if y.size < 10 * (x.shape[1] + owned.shape[1]) or not np.any(y):
        return None  # too few samples, or an error exactly 0 (a channel not logged)
    apart = _told_apart(x, owned)
    lasso = np.zeros(x.shape[1])
    lasso[apart] = sparse_coefficients(np.hstack([x[:, apart], owned]), y,
                                       intercept=False)[:len(apart)]
    weight = np.abs(lasso) * np.sqrt(np.mean(x * x, axis=0))
    kept = [int(i) for i in np.argsort(-weight) if weight[i] > 0][:MAX_KEPT] \
        or _strongest(x[:, apart], y, owned, apart)
    coef, t = ordinary_fit(np.hstack([x[:, kept], owned]), y)
    while len(kept) > 1 and t[:len(kept)].min() < Z_VIOLATED:
        kept.pop(int(np.argmin(t[:len(kept)])))
        coef, t = ordinary_fit(np.hstack([x[:, kept], owned]), y)
    contribution = x[:, kept] @ coef[:len(kept)]
    selected = [Selected(terms[column], float(coef[i]), float(t[i]),
                         abs(float(coef[i])) * float(np.sqrt(np.mean(x[:, column] ** 2))),
                         tuple(terms[a] for a in _alike(x, owned, column, apart)))
                for i, column in enumerate(kept)]
    return Fitted(selected, float(np.sqrt(np.mean(contribution ** 2))),
                  _joint_z(x[:, kept], owned, y))


def _told_apart(x: np.ndarray, owned: np.ndarray) -> list[int]:
    """The columns of ``x`` the samples tell apart from the owned ones and from the columns
    before them: a column within SPANNED of their span, or within ALIKE of one of them alone
    (beside the owned ones), relative, is left out. On the steady braking samples
    '[P > 0.5 bar]' and '[braked before]' are one column, and 'sgn ω·[P > 0.5 bar]' differs
    only where the wheel locked (the two shared 150 N m out half and half); a column a
    little apart from several, as e³ from 1, e, e² on the valve's map, is the lasso's to
    judge."""
    chosen: list[int] = []
    for column in range(x.shape[1]):
        if _residual(x[:, column], np.hstack([owned, x[:, chosen]])) > SPANNED and not any(
                _residual(x[:, column], np.hstack([owned, x[:, [c]]])) <= ALIKE
                for c in chosen):
            chosen.append(column)
    return chosen


def _residual(target: np.ndarray, design: np.ndarray) -> float:
    """How far ``target`` is from the span of ``design``'s columns, relative to its norm."""
    coef, *_ = np.linalg.lstsq(design, target, rcond=None)
    return float(np.linalg.norm(target - design @ coef) / max(np.linalg.norm(target), 1e-300))


def _alike(x: np.ndarray, owned: np.ndarray, column: int, apart: Sequence[int]) -> list[int]:
    """The columns left out as not told apart that repeat ``column`` alone (beside the owned
    ones) within ALIKE, the closest first: the samples cannot say which of them the error
    holds; a fit of the rig's runs can ('[braked before]' and '[P > 0.5 bar]' part where an
    oscillating brake releases)."""
    design = np.hstack([owned, x[:, [column]]])
    near = {other: _residual(x[:, other], design)
            for other in set(range(x.shape[1])) - set(apart)}
    return sorted((o for o, r in near.items() if r <= ALIKE), key=lambda o: (near[o], o))


def _joint_z(kept: np.ndarray, owned: np.ndarray, y: np.ndarray) -> float:
    """√(Δχ²) of ``y``'s fit on ``owned`` with and without ``kept``, the variance over the
    error's effective count."""
    def residual(design: np.ndarray) -> np.ndarray:
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        return y - design @ coef
    without, with_ = residual(owned), residual(np.hstack([kept, owned]))
    variance = float(with_ @ with_) / effective_count(with_)
    return float(np.sqrt(max(float(without @ without - with_ @ with_), 0.0) / variance))


def _strongest(x: np.ndarray, y: np.ndarray, owned: np.ndarray, columns: list[int]
               ) -> list[int]:
    """The one of ``columns`` (of ``x``, whose columns they are) that, beside the owned
    ones, explains most of ``y`` (the relation is checked on it when the lasso keeps none):
    every column of a library of dozens fitted at once shares out what one term holds."""
    def left(i: int) -> float:
        design = np.hstack([x[:, [i]], owned])
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        residual = y - design @ coef
        return float(residual @ residual)
    return [columns[min(range(x.shape[1]), key=left)]] if x.shape[1] else []


def significant(fitted: Fitted, rows: Sequence[Rows], min_effect: float = MIN_EFFECT) -> bool:
    return fitted.z > Z_VIOLATED and fitted.effect > floor_of(rows, min_effect) \
        and all(s.t > Z_VIOLATED for s in fitted.selected)


def floor_of(rows: Sequence[Rows], min_effect: float = MIN_EFFECT) -> float:
    """The effect below which a term does not matter: ``min_effect`` of the equation's scale,
    or NOISE_FLOOR times what the regressors' noise makes of the error (a counted wheel
    channel's slip, σ 0.03 at 64 lines, reads as a friction curve of another shape:
    errors in the variables)."""
    noise = float(np.sqrt(np.mean([r.noise ** 2 for r in rows])))
    return max(min_effect * scale_of(rows), NOISE_FLOOR * noise)


def input_noise_of(rows: Sequence[Rows]) -> float:
    """NOISE_FLOOR times what the inputs' noise makes of the error, over ``rows``: a
    deviation within it is no structure of its own (:attr:`Check.input_noise`)."""
    return NOISE_FLOOR * float(np.sqrt(np.mean([r.input_noise ** 2 for r in rows])))


def scale_of(rows: Sequence[Rows]) -> float:
    return float(np.mean([r.scale for r in rows]))


def ordinary_fit(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """y ≈ x c by least squares: c and |c| over its standard error, the residual's
    variance taken over its effective count (an equation's error is not white)."""
    # columns scaled to one rms first: a library's terms span twenty decades (|P|·P against
    # a step), and the pseudo-inverse's cut-off then read a step's σ as 0
    spread = np.sqrt(np.mean(x * x, axis=0))
    spread[spread == 0] = 1.0
    scaled = x / spread
    coef, *_ = np.linalg.lstsq(scaled, y, rcond=None)
    residual = y - scaled @ coef
    variance = float(residual @ residual) / effective_count(residual)
    # a variance rounding made negative is an unknown σ: no significance (it had been NaN)
    diagonal = np.diag(np.linalg.pinv(scaled.T @ scaled))
    std = np.where(diagonal > 0.0, np.sqrt(np.abs(diagonal) * variance), np.inf)
    return coef / spread, np.abs(coef) / np.maximum(std, 1e-300)
