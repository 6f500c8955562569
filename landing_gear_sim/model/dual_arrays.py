"""Arrays of dual numbers for the compiled kernels: the parameter vector, the states and the
records of a dual pass (:mod:`landing_gear_sim.model.dual` holds the number itself).

:class:`DualVector` holds values (n,) and their derivatives (n, lanes); read or written element
by element in compiled code it gives and takes duals. :class:`DualRows` holds a kernel's
records, (n, m) and (n, m, lanes). :func:`vector_like` and :func:`rows_like` allocate the
kernel's scratch as plain arrays or dual ones, following the parameter vector: the kernel's
source is one for both.
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import (
    NativeValue,
    intrinsic,
    make_attribute_wrapper,
    models,
    overload,
    overload_attribute,
    register_model,
    typeof_impl,
    unbox,
)

from landing_gear_sim.model.dual import (
    DualType,
    as_dual,
    dual_from,
    is_dual,
    is_scalar,
    tangents_of,
)


class DualVector:
    """Values (n,) and their derivatives (n, lanes), read and written element by element as
    duals in compiled code: the parameter vector and the states of a dual kernel."""

    def __init__(self, values: np.ndarray, tangents: np.ndarray) -> None:
        self.values = np.ascontiguousarray(values, dtype=float)
        self.tangents = np.ascontiguousarray(tangents, dtype=float)
        if self.tangents.shape[:1] != self.values.shape or self.tangents.ndim != 2:
            raise ValueError(f"tangents {self.tangents.shape} do not match values "
                             f"{self.values.shape}")

    @property
    def lanes(self) -> int:
        return int(self.tangents.shape[1])


class DualVectorType(types.Type):
    """:class:`DualVector` (numba type)."""

    def __init__(self, lanes: int) -> None:
        self.lanes = lanes
        self.dual = DualType(lanes)
        super().__init__(name=f"DualVector({lanes})")


@register_model(DualVectorType)
class _DualVectorModel(models.StructModel):
    MEMBERS = (("values", types.float64[::1]), ("tangents", types.float64[:, ::1]))

    def __init__(self, dmm: Any, fe_type: DualVectorType) -> None:
        super().__init__(dmm, fe_type, list(self.MEMBERS))


make_attribute_wrapper(DualVectorType, "values", "values")
make_attribute_wrapper(DualVectorType, "tangents", "tangents")


@typeof_impl.register(DualVector)
def _typeof(val: DualVector, c: Any) -> DualVectorType:
    return DualVectorType(val.lanes)


@unbox(DualVectorType)
def _unbox(typ: DualVectorType, obj: Any, c: Any) -> NativeValue:
    return _unbox_arrays(typ, obj, c, _DualVectorModel.MEMBERS)


def _unbox_arrays(typ: types.Type, obj: Any, c: Any,
                  members: tuple[tuple[str, types.Array], ...]) -> NativeValue:
    """A Python object's array attributes ``members`` as the struct of ``typ``."""
    struct = cgutils.create_struct_proxy(typ)(c.context, c.builder)
    for name, arraytype in members:
        member = c.pyapi.object_getattr_string(obj, name)
        setattr(struct, name, c.unbox(arraytype, member).value)
        c.pyapi.decref(member)
    return NativeValue(struct._getvalue())


@intrinsic
def _vector(typingctx, values, tangents, like):
    """A vector of ``values`` and ``tangents`` with the lanes of ``like`` (a vector, or rows
    of them)."""
    vectortype = like.row if isinstance(like, DualRowsType) else like
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        vector = cgutils.create_struct_proxy(signature.return_type)(context, builder)
        vector.values, vector.tangents = args[0], args[1]
        context.nrt.incref(builder, signature.args[0], args[0])
        context.nrt.incref(builder, signature.args[1], args[1])
        return vector._getvalue()
    return vectortype(values, tangents, like), codegen


def _pointers(context: Any, builder: Any, vectortype: DualVectorType, vector: Any,
              index: Any, indextype: types.Type) -> tuple[Any, list[Any]]:
    """Where element ``index``'s value and its tangents lie (no reference taken: a read
    or write through attributes took and dropped two per element)."""
    proxy = cgutils.create_struct_proxy(vectortype)(context, builder, value=vector)
    values = context.make_array(types.float64[::1])(context, builder, proxy.values)
    tangents = context.make_array(types.float64[:, ::1])(context, builder, proxy.tangents)
    i = context.cast(builder, index, indextype, types.intp)
    row = builder.mul(i, context.get_constant(types.intp, vectortype.lanes))
    return builder.gep(values.data, [i]), [
        builder.gep(tangents.data, [builder.add(row, context.get_constant(types.intp, k))])
        for k in range(vectortype.lanes)]


@intrinsic
def _load(typingctx, vector, i):
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        value, tangents = _pointers(context, builder, signature.args[0], args[0], args[1],
                                    signature.args[1])
        return dual_from(builder, context, signature.return_type, builder.load(value),
                     [builder.load(t) for t in tangents])
    return vector.dual(vector, i), codegen


@intrinsic
def _store(typingctx, vector, i, dual):
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        value, tangents = _pointers(context, builder, signature.args[0], args[0], args[1],
                                    signature.args[1])
        builder.store(builder.extract_value(args[2], 0), value)
        for t, d in zip(tangents, tangents_of(builder, args[2], signature.args[0].lanes),
                        strict=True):
            builder.store(d, t)
        return context.get_dummy_value()
    return types.void(vector, i, dual), codegen


@overload(operator.getitem)
def _getitem(vector, i) -> Callable[..., Any] | None:
    if isinstance(vector, DualVectorType) and isinstance(i, types.Integer):
        return lambda vector, i: _load(vector, i)
    return None


@overload(operator.setitem)
def _setitem(vector, i, x) -> Callable[..., Any] | None:
    if not isinstance(vector, DualVectorType):
        return None
    if isinstance(i, types.Integer) and is_dual(x):
        return lambda vector, i, x: _store(vector, i, x)
    if isinstance(i, types.Integer) and is_scalar(x):
        return lambda vector, i, x: _store(vector, i, as_dual(x * 1.0, _load(vector, i)))
    if isinstance(i, types.SliceType) and (is_dual(x) or is_scalar(x)):
        def fill(vector, i, x):
            start, stop, step = i.indices(vector.values.size)
            for j in range(start, stop, step):
                vector[j] = x
        return fill
    return None


@overload_attribute(DualVectorType, "size")
def _size(vector) -> Callable[..., Any]:
    return lambda vector: vector.values.size


@overload(len)
def _len(vector) -> Callable[..., Any] | None:
    return (lambda vector: vector.values.size) if isinstance(vector, DualVectorType) else None


def vector_like(like: Any, n: int) -> Any:
    """Zeros (n,): a float array, or a :class:`DualVector` with ``like``'s lanes."""
    raise NotImplementedError("compiled only")


@overload(vector_like)
def _vector_like(like, n) -> Callable[..., Any]:
    if isinstance(like, DualVectorType):
        lanes = like.lanes
        return lambda like, n: _vector(np.zeros(n), np.zeros((n, lanes)), like)
    return lambda like, n: np.zeros(n)


def rows_like(like: Any, rows: int, n: int) -> Any:
    """``rows`` zero vectors (n,) to index as ``work[k]``: a float array (rows, n), or a
    tuple of :class:`DualVector` with ``like``'s lanes (``rows`` a constant)."""
    raise NotImplementedError("compiled only")


@overload(rows_like, prefer_literal=True)
def _rows_like(like, rows, n) -> Callable[..., Any] | None:
    if not isinstance(like, DualVectorType):
        return lambda like, rows, n: np.zeros((rows, n))
    if not isinstance(rows, types.IntegerLiteral):
        return None
    vectors = ", ".join(["vector_like(like, n)"] * rows.literal_value)
    scope: dict[str, Any] = {"vector_like": vector_like}
    exec(f"def rows(like, rows, n):\n    return ({vectors},)", scope)
    return scope["rows"]


class DualRows:
    """Rows of duals: values (n, m) and their derivatives (n, m, lanes); row k, read in
    compiled code, is a :class:`DualVector` of the two arrays' row k (a kernel's record)."""

    def __init__(self, values: np.ndarray, tangents: np.ndarray) -> None:
        self.values = np.ascontiguousarray(values, dtype=float)
        self.tangents = np.ascontiguousarray(tangents, dtype=float)
        if self.tangents.shape[:2] != self.values.shape or self.tangents.ndim != 3:
            raise ValueError(f"tangents {self.tangents.shape} do not match values "
                             f"{self.values.shape}")


class DualRowsType(types.Type):
    """:class:`DualRows` (numba type)."""

    def __init__(self, lanes: int) -> None:
        self.lanes = lanes
        self.row = DualVectorType(lanes)
        super().__init__(name=f"DualRows({lanes})")


@register_model(DualRowsType)
class _DualRowsModel(models.StructModel):
    MEMBERS = (("values", types.float64[:, ::1]), ("tangents", types.float64[:, :, ::1]))

    def __init__(self, dmm: Any, fe_type: DualRowsType) -> None:
        super().__init__(dmm, fe_type, list(self.MEMBERS))


make_attribute_wrapper(DualRowsType, "values", "values")
make_attribute_wrapper(DualRowsType, "tangents", "tangents")


@typeof_impl.register(DualRows)
def _typeof_rows(val: DualRows, c: Any) -> DualRowsType:
    return DualRowsType(int(val.tangents.shape[2]))


@unbox(DualRowsType)
def _unbox_rows(typ: DualRowsType, obj: Any, c: Any) -> NativeValue:
    return _unbox_arrays(typ, obj, c, _DualRowsModel.MEMBERS)


@overload(operator.getitem)
def _row(rows, k) -> Callable[..., Any] | None:
    if not (isinstance(rows, DualRowsType) and isinstance(k, types.Integer)):
        return None
    return lambda rows, k: _vector(rows.values[k], rows.tangents[k], rows)
