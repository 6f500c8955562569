"""Dual numbers for numba: the plant's own step functions, compiled once more, carry the
derivatives of every state with respect to chosen parameters in the same pass as the states.

Why dual numbers (forward-mode automatic differentiation) and not the alternatives:

* forward sensitivity equations beside the RK4 step would need ∂f/∂x and ∂f/∂θ of every
  law: each balance written a second time, by hand, and kept in step with the first;
* complex steps give one derivative per pass (no gain over differences), and numba cannot
  order complex numbers (the plant branches on the slip's sign, on a locked wheel);
* JAX or PyTorch would mean a second plant beside the numba one.

Here a law is written once, with ordinary operators and ``math`` functions on ``p[K]`` and
``x[K]``. :class:`~landing_gear_sim.model.dual_arrays.DualVector` (values and their
tangents, (n,) and (n, lanes)) takes the place of the parameter vector and the state arrays:
reading an element gives a :class:`DualType` value (the value and one derivative per lane, a
flat struct the compiler keeps in registers), and every operator and function the physics
uses is overloaded for it below. Branches follow the values, so the derivative is that of
the path the plain simulation takes: the plain kernel and its dual compile from the same
source, and the dual one's values are the plain one's to the bit.

The lane count is part of the type: each count compiles the kernel once (cached on disk);
:func:`lanes_for` rounds a count up to the few that are compiled. LLVM's loop vectorizer is
off while a dual kernel compiles (:func:`call_dual`): it turned the per-lane
arithmetic into shuffles that cost up to 4× (a 4-lane stop took 8× a plain one, 2.2× without
it); the plain kernels lose nothing without it either (measured: within 2 %).
"""

from __future__ import annotations

import math
import operator
import threading
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit, types
from numba.core import cgutils, config
from numba.core.typeconv import Conversion
from numba.extending import (
    intrinsic,
    lower_cast,
    models,
    overload,
    register_model,
)

LANES = (2, 4, 8)
"""The lane counts a dual kernel is compiled for (a count between is rounded up)."""

_SCALARS = (types.Float, types.Integer, types.Boolean)


class DualType(types.Type):
    """A value and its derivatives along ``lanes`` directions (numba type)."""

    def __init__(self, lanes: int) -> None:
        self.lanes = lanes
        super().__init__(name=f"Dual({lanes})")

    def unify(self, typingctx: Any, other: types.Type) -> types.Type | None:
        # a variable that is 0.0 on one branch and a dual on the other is a dual
        return self if isinstance(other, _SCALARS) else None

    def can_convert_from(self, typingctx: Any, other: types.Type) -> Conversion | None:
        return Conversion.promote if isinstance(other, _SCALARS) else None


@register_model(DualType)
class _DualModel(models.StructModel):
    def __init__(self, dmm: Any, fe_type: DualType) -> None:
        # flat: a nested tuple of tangents cost 2-4x in LLVM's aggregate handling
        super().__init__(dmm, fe_type, [("v", types.float64)]
                         + [(f"d{k}", types.float64) for k in range(fe_type.lanes)])


def dual_from(builder: Any, context: Any, typ: DualType, value: Any, tangents: list[Any]
              ) -> Any:
    """LLVM: the dual of ``typ`` with ``value`` and ``tangents``."""
    out = cgutils.get_null_value(context.get_value_type(typ))
    out = builder.insert_value(out, value, 0)
    for k, tangent in enumerate(tangents):
        out = builder.insert_value(out, tangent, k + 1)
    return out


def tangents_of(builder: Any, dual: Any, lanes: int) -> list[Any]:
    """LLVM: a dual's derivatives."""
    return [builder.extract_value(dual, k + 1) for k in range(lanes)]


@intrinsic
def value_of(typingctx, a):
    """A dual's value (a float)."""
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.extract_value(args[0], 0)
    return types.float64(a), codegen


@intrinsic
def _combined(typingctx, v, a, ca, b, cb):
    """The dual of value ``v`` and derivatives ca·a' + cb·b' (the chain rule of a binary
    operation)."""
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        value, da, x, db, y = args
        lanes = signature.return_type.lanes
        tangents = [builder.fadd(builder.fmul(x, s), builder.fmul(y, t)) for s, t in
                    zip(tangents_of(builder, da, lanes), tangents_of(builder, db, lanes),
                        strict=True)]
        return dual_from(builder, context, signature.return_type, value, tangents)
    return a(types.float64, a, types.float64, b, types.float64), codegen


@intrinsic
def _scaled(typingctx, v, a, ca):
    """The dual of value ``v`` and derivatives ca·a' (the chain rule of a function)."""
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        value, da, x = args
        tangents = [builder.fmul(x, t)
                    for t in tangents_of(builder, da, signature.return_type.lanes)]
        return dual_from(builder, context, signature.return_type, value, tangents)
    return a(types.float64, a, types.float64), codegen


@intrinsic
def _lifted(typingctx, v, like):
    """The number ``v`` as a dual of ``like``'s lanes, its derivatives 0 (not 0·``like``'s:
    those may be a NaN)."""
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        zero = context.get_constant(types.float64, 0.0)
        return dual_from(builder, context, signature.return_type, args[0],
                         [zero] * signature.return_type.lanes)
    return like(types.float64, like), codegen


@lower_cast(types.Float, DualType)
@lower_cast(types.Integer, DualType)
@lower_cast(types.Boolean, DualType)
def _constant(context: Any, builder: Any, fromty: types.Type, toty: DualType, val: Any) -> Any:
    zero = context.get_constant(types.float64, 0.0)
    return dual_from(builder, context, toty, context.cast(builder, val, fromty, types.float64),
                 [zero] * toty.lanes)


def is_dual(t: types.Type) -> bool:
    """Whether a numba type is a dual."""
    return isinstance(t, DualType)


def is_scalar(t: types.Type) -> bool:
    """Whether a numba type is a plain number (a float, an integer, a truth)."""
    return isinstance(t, _SCALARS)


def _binary(op: Callable[..., Any], both: Callable[..., Any], left: Callable[..., Any],
            right: Callable[..., Any]) -> None:
    """Overload ``op`` for (dual, dual), (dual, scalar) and (scalar, dual)."""
    @overload(op)
    def _impl(a, b) -> Callable[..., Any] | None:
        if is_dual(a) and is_dual(b):
            return both
        if is_dual(a) and is_scalar(b):
            return left
        if is_scalar(a) and is_dual(b):
            return right
        return None


def _add(a, b):
    return a + b


def _sub(a, b):
    return a - b


def _mul(a, b):
    return a * b


def _div(a, b):
    return a / b


_binary(operator.add, lambda a, b: _combined(value_of(a) + value_of(b), a, 1.0, b, 1.0),
        lambda a, b: _scaled(value_of(a) + b, a, 1.0),
        lambda a, b: _scaled(a + value_of(b), b, 1.0))
_binary(operator.sub, lambda a, b: _combined(value_of(a) - value_of(b), a, 1.0, b, -1.0),
        lambda a, b: _scaled(value_of(a) - b, a, 1.0),
        lambda a, b: _scaled(a - value_of(b), b, -1.0))
_binary(operator.mul,
        lambda a, b: _combined(value_of(a) * value_of(b), a, value_of(b), b, value_of(a)),
        lambda a, b: _scaled(value_of(a) * b, a, b * 1.0),
        lambda a, b: _scaled(a * value_of(b), b, a * 1.0))
_binary(operator.truediv,
        lambda a, b: _combined(value_of(a) / value_of(b), a, 1.0 / value_of(b), b,
                               -value_of(a) / (value_of(b) * value_of(b))),
        lambda a, b: _scaled(value_of(a) / b, a, 1.0 / b),
        lambda a, b: _scaled(a / value_of(b), b, -a / (value_of(b) * value_of(b))))
for _inplace, _plain in ((operator.iadd, _add), (operator.isub, _sub),
                         (operator.imul, _mul), (operator.itruediv, _div)):
    _binary(_inplace, _plain, _plain, _plain)


def _comparison(op: Callable[[Any, Any], bool]) -> None:
    """Overload an ordering: duals order by value (branches follow the plain path)."""
    _binary(op, lambda a, b: op(value_of(a), value_of(b)), lambda a, b: op(value_of(a), b),
            lambda a, b: op(a, value_of(b)))


for _op in (operator.lt, operator.le, operator.gt, operator.ge):
    _comparison(_op)


@intrinsic
def _constant_tangents(typingctx, a):
    """Whether every derivative of a dual is 0."""
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        zero = context.get_constant(types.float64, 0.0)
        constant = context.get_constant(types.boolean, True)
        for t in tangents_of(builder, args[0], signature.args[0].lanes):
            constant = builder.and_(constant, builder.fcmp_ordered("==", t, zero))
        return constant
    return types.boolean(a), codegen


# Equality is that of first-order jets: a dual equals a number when its value does and it
# does not move. The physics asks "x != 0" to skip a term that adds nothing (a slot's
# coefficient, a disc's run-out); a coefficient at 0 that is being fitted does add something
# along its direction, and compared by value alone its derivative read 0.
_binary(operator.eq,
        lambda a, b: value_of(a) == value_of(b) and _constant_tangents(a - b),
        lambda a, b: value_of(a) == b and _constant_tangents(a),
        lambda a, b: a == value_of(b) and _constant_tangents(b))
_binary(operator.ne,
        lambda a, b: not (value_of(a) == value_of(b) and _constant_tangents(a - b)),
        lambda a, b: not (value_of(a) == b and _constant_tangents(a)),
        lambda a, b: not (a == value_of(b) and _constant_tangents(b)))


@overload(operator.neg)
def _neg(a) -> Callable[..., Any] | None:
    return (lambda a: _scaled(-value_of(a), a, -1.0)) if is_dual(a) else None


@overload(operator.pow)
def _pow(a, b) -> Callable[..., Any] | None:
    if not (is_dual(a) and is_scalar(b)):
        return None

    def power(a, b):
        x = value_of(a)
        return _scaled(x ** b, a, b * x ** (b - 1) if b != 0 else 0.0)
    return power


def _function(fns: tuple[Callable[..., Any], ...],
              value_and_slope: Callable[[float], tuple[float, float]]) -> None:
    """Overload the one-argument functions ``fns`` for duals by their value and slope."""
    for fn in fns:
        @overload(fn)
        def _impl(a) -> Callable[..., Any] | None:
            if not is_dual(a):
                return None

            def chained(a):
                value, slope = value_and_slope(value_of(a))
                return _scaled(value, a, slope)
            return chained


@njit(inline="always")
def _exp(x):
    e = math.exp(x)
    return e, e


@njit(inline="always")
def _sqrt(x):
    root = math.sqrt(x)
    return root, 0.5 / root if root > 0.0 else 0.0


@njit(inline="always")
def _log(x):
    return math.log(x), 1.0 / x


@njit(inline="always")
def _log1p(x):
    return math.log1p(x), 1.0 / (1.0 + x)


@njit(inline="always")
def _cos(x):
    return math.cos(x), -math.sin(x)


@njit(inline="always")
def _sin(x):
    return math.sin(x), math.cos(x)


@njit(inline="always")
def _tanh(x):
    t = math.tanh(x)
    return t, 1.0 - t * t


@njit(inline="always")
def _abs(x):
    # at 0 the slope of the path a plain run takes there: none (a lock holds ω at 0)
    return abs(x), 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


_function((math.exp, np.exp), _exp)
_function((math.sqrt, np.sqrt), _sqrt)
_function((math.log, np.log), _log)
_function((math.log1p, np.log1p), _log1p)
_function((math.cos, np.cos), _cos)
_function((math.sin, np.sin), _sin)
_function((math.tanh, np.tanh), _tanh)
_function((abs, np.abs), _abs)


def _of_value(fn: Callable[..., Any]) -> None:
    """Overload a function whose result is the plain function of the value (a sign, an
    integer part, a truth): piecewise constant, no derivative."""
    @overload(fn)
    def _impl(a) -> Callable[..., Any] | None:
        return (lambda a: fn(value_of(a))) if is_dual(a) else None


for _fn in (np.sign, int, math.floor, math.ceil, bool):
    _of_value(_fn)


@overload(float)
def _float(a) -> Callable[..., Any] | None:
    return (lambda a: a) if is_dual(a) else None


def as_dual(x: Any, like: Any) -> Any:
    """``x`` as a dual with ``like``'s lanes (zero derivatives for a scalar); ``x`` itself
    when ``like`` is no dual."""
    raise NotImplementedError("compiled only")


@overload(as_dual)
def _as_dual(x, like) -> Callable[..., Any]:
    if not is_dual(like) or is_dual(x):
        return lambda x, like: x
    return lambda x, like: _lifted(x * 1.0, like)


def _extreme(fns: tuple[Callable[..., Any], ...], first: Callable[[Any, Any], bool]) -> None:
    """Overload a two-argument max or min: the derivative of the argument it picks."""
    for fn in fns:
        @overload(fn)
        def _impl(a, b) -> Callable[..., Any] | None:
            if not ((is_dual(a) or is_dual(b)) and all(is_dual(t) or is_scalar(t)
                                                          for t in (a, b))):
                return None
            return lambda a, b: as_dual(a, b) if first(a, b) else as_dual(b, a)


_extreme((max, np.maximum), njit(lambda a, b: a >= b))
_extreme((min, np.minimum), njit(lambda a, b: a <= b))


@overload(max)
def _max3(a, b, c) -> Callable[..., Any] | None:
    return (lambda a, b, c: max(max(a, b), c)) if any(map(is_dual, (a, b, c))) else None


@overload(min)
def _min3(a, b, c) -> Callable[..., Any] | None:
    return (lambda a, b, c: min(min(a, b), c)) if any(map(is_dual, (a, b, c))) else None


@overload(operator.getitem)
def _mixed_getitem(signals, i) -> Callable[..., Any] | None:
    """A tuple of duals and scalars (an equation's signals, zeros among them) read at a
    run-time index: every element as a dual."""
    if not (isinstance(signals, types.Tuple) and isinstance(i, types.Integer)
            and any(map(is_dual, signals.types))
            and all(is_dual(t) or is_scalar(t) for t in signals.types)):
        return None
    first = next(k for k, t in enumerate(signals.types) if is_dual(t))
    lines = ["def read(signals, i):", f"    like = signals[{first}]"]
    for k in range(len(signals.types)):
        lines += [f"    if i == {k}:", f"        return as_dual(signals[{k}], like)"]
    lines.append("    return as_dual(0.0, like)")
    scope: dict[str, Any] = {"as_dual": as_dual}
    exec("\n".join(lines), scope)  # an if-chain over the tuple's own length
    return scope["read"]


_compiling = threading.Lock()


def call_dual(kernel: Any, *args: Any) -> Any:
    """Call a compiled ``kernel`` with dual arguments. A first call with these argument
    types compiles (or loads) it with LLVM's loop vectorizer off (see the module's note);
    the setting is numba's, for the whole process, so only while that compilation runs. A
    later call with other types (a run that follows a measured wheel angle) compiles its
    own, off too: compiled with it on, the same derivatives came out different in their last
    bits, and slower."""
    signature = tuple(kernel.typeof_pyval(arg) for arg in args)
    if signature not in kernel.overloads:
        with _compiling:
            # read from the environment when numba loads: not in its stubs
            before = config.LOOP_VECTORIZE  # type: ignore[attr-defined]
            config.LOOP_VECTORIZE = 0  # type: ignore[attr-defined]
            try:
                kernel.compile(signature)
            finally:
                config.LOOP_VECTORIZE = before  # type: ignore[attr-defined]
    return kernel(*args)


def lanes_for(count: int) -> int:
    """The compiled lane count for ``count`` directions (at most the largest: more
    directions take more passes)."""
    return next((lanes for lanes in LANES if lanes >= count), LANES[-1])
