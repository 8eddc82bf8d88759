"""Vector lanes as values: eight float32 states in one register, for numba kernels.

numba vectorizes loops, not values: a loop over eight lanes pays for its set-up, its
alias checks and its remainder every time it runs (measured: 40-60 cycles a loop, against
a few cycles of arithmetic), and a state test is hundreds of such small loops. Here a
lane vector is a value of its own type, :data:`f8` (LLVM's ``<8 x float>``: one AVX
register, half an AVX-512 one), with its operations lowered to single vector
instructions, so a kernel reads like VAMP's: straight-line arithmetic on whole lane
vectors, with scalar control flow (loops over joints, spheres and obstacles) around it.

* ``load(a, i)``, ``store(a, i, v)``: eight consecutive float32 of a 1-d C array from
  index ``i``; ``splat(x)``: a scalar in every lane; ``lane(v, k)``: one lane's value.
* ``+ - *``, unary ``-``, ``fma(a, b, c) = a * b + c``, ``vmin``, ``vmax``, ``vabs``,
  ``vsqrt``, ``vfloor``; comparisons ``< <= > >=`` give a :data:`m8` mask; masks combine
  with ``& | ~`` and are read with ``any_lane``, ``all_lanes``, ``mask_bits``;
  ``select(mask, a, b)``.

The same functions take float64 scalars (``load`` of a float64 array gives one scalar),
so code written on them runs as eight float32 lanes or as one float64 state: the one
kinematics of :mod:`plannerlab.collision.kinematics` is written once for both.
"""

from __future__ import annotations

import math
import operator
from typing import Any, cast

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic, models, overload, register_model

#: lanes in a vector
LANES = 8

#: the decorator of the collision core's and the compiled planners' hot kernels: compiled
#: and cached, no GIL, and no reference counting (numba's NRT): they allocate nothing and
#: take every array from their caller, so a named tuple of arrays passed on costs no
#: increments and decrements of each array's count (measured ~2 000 cycles a call for the
#: model). (``_nrt`` is numba's own keyword, outside its typed signature.)
kernel: Any = cast(Any, njit)(cache=True, nogil=True, _nrt=False)
#: the same, inlined into its caller by numba (the state test's passes: out of line each
#: call handed over the model and the scratch, some 80 arrays, on the stack)
inline_kernel: Any = cast(Any, njit)(cache=True, nogil=True, inline="always", _nrt=False)


@intrinsic
def _unliteral(typingctx, x):
    """``x`` as a run-time value: a constant's plain type (int64, bool, a tuple of them)
    instead of numba's ``Literal[int](1)``. A kernel is compiled once per distinct argument
    types, and numba types a constant argument as its literal, so a kernel called with
    ``ANY_HIT`` in one place, ``EVERY_LANE`` in another and a variable in a third is
    compiled three times (the state test: ~5 s each on a cold cache). Pass constants
    through this where a kernel is also called with other values; a variable first bound
    to a constant and then changed in a loop (``top = 0 ... top += 1``) is typed as the
    literal too for a first, wasted compile, so bind it as ``unliteral(0)``. The value
    stays a constant in the caller's LLVM code: where LLVM inlines the callee it still
    folds it."""
    ty = types.unliteral(x)

    def codegen(context, builder, sig, args):
        return context.cast(builder, args[0], sig.args[0], sig.return_type)

    return ty(x), codegen


#: (typed Any for mypy, as the other intrinsics: called from kernels with one argument)
unliteral: Any = _unliteral

_F32 = ir.FloatType()
_VEC = ir.VectorType(_F32, LANES)
_MASK = ir.VectorType(ir.IntType(1), LANES)
_I32 = ir.IntType(32)


class F8(types.Type):
    """Eight float32 lanes (LLVM ``<8 x float>``)."""

    def __init__(self) -> None:
        super().__init__(name="f32x8")


class M8(types.Type):
    """A mask over eight lanes (LLVM ``<8 x i1>``)."""

    def __init__(self) -> None:
        super().__init__(name="mask8")


f8 = F8()
m8 = M8()


@register_model(F8)
class _F8Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _VEC)


@register_model(M8)
class _M8Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _MASK)


def _is32(t) -> bool:
    return isinstance(t, types.Array) and t.dtype == types.float32


# ------------------------------------------------------------------ memory
@intrinsic
def _vload(typingctx, arr, idx):
    sig = f8(arr, types.intp)

    def codegen(context, builder, signature, args):
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        ptr = builder.gep(ary.data, [args[1]])
        return builder.load(builder.bitcast(ptr, _VEC.as_pointer()), align=4)

    return sig, codegen


@intrinsic
def _vstore(typingctx, arr, idx, v):
    sig = types.void(arr, types.intp, f8)

    def codegen(context, builder, signature, args):
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        ptr = builder.gep(ary.data, [args[1]])
        builder.store(args[2], builder.bitcast(ptr, _VEC.as_pointer()), align=4)
        return context.get_dummy_value()

    return sig, codegen


def load(a, i):
    """Eight float32 lanes ``a[i:i + 8]`` (a float64 array: the one value ``a[i]``)."""
    raise NotImplementedError("numba only")


def store(a, i, v):
    """``a[i:i + 8] = v`` (a float64 array: ``a[i] = v``)."""
    raise NotImplementedError("numba only")


@overload(load)
def _ov_load(a, i):
    if _is32(a):
        return lambda a, i: _vload(a, i)
    if isinstance(a, types.Array):
        return lambda a, i: a[i]
    return None


@overload(store)
def _ov_store(a, i, v):
    if _is32(a) and v == f8:
        return lambda a, i, v: _vstore(a, i, v)
    if isinstance(a, types.Array) and isinstance(v, types.Float):

        def impl(a, i, v):
            a[i] = v

        return impl
    return None


@intrinsic
def _vsplat(typingctx, x):
    sig = f8(types.float32)

    def codegen(context, builder, signature, args):
        v = ir.Constant(_VEC, ir.Undefined)
        v = builder.insert_element(v, args[0], ir.Constant(_I32, 0))
        zeros = ir.Constant(ir.VectorType(_I32, LANES), [0] * LANES)
        return builder.shuffle_vector(v, v, zeros)

    return sig, codegen


def splat(x):
    """A float32 scalar in every lane."""
    raise NotImplementedError("numba only")


@overload(splat)
def _ov_splat(x):
    if isinstance(x, types.Float | types.Integer):
        return lambda x: _vsplat(np.float32(x))
    return None


@intrinsic
def _vlane(typingctx, v, k):
    sig = types.float32(f8, types.intp)

    def codegen(context, builder, signature, args):
        return builder.extract_element(args[0], builder.trunc(args[1], _I32))

    return sig, codegen


def lane(v, k):
    """Lane k's value (float32)."""
    raise NotImplementedError("numba only")


@overload(lane)
def _ov_lane(v, k):
    if v == f8:
        return lambda v, k: _vlane(v, k)
    return None


# ------------------------------------------------------------------ arithmetic
def _vec_binop(name):
    @intrinsic
    def op(typingctx, a, b):
        sig = f8(f8, f8)

        def codegen(context, builder, signature, args):
            return getattr(builder, name)(args[0], args[1])

        return sig, codegen

    return op


_vadd, _vsub, _vmul, _vdiv = (_vec_binop(n) for n in ("fadd", "fsub", "fmul", "fdiv"))

for _op, _impl in (
    (operator.add, _vadd),
    (operator.sub, _vsub),
    (operator.mul, _vmul),
    (operator.truediv, _vdiv),
):

    def _make(impl):
        def ov(a, b):
            if a == f8 and b == f8:
                return lambda a, b: impl(a, b)
            return None

        return ov

    overload(_op)(_make(_impl))


@intrinsic
def _vneg(typingctx, a):
    sig = f8(f8)

    def codegen(context, builder, signature, args):
        return builder.fneg(args[0])

    return sig, codegen


@overload(operator.neg)
def _ov_neg(a):
    if a == f8:
        return lambda a: _vneg(a)
    return None


def _call(builder, name, args):
    fnty = ir.FunctionType(_VEC, [_VEC] * len(args))
    return builder.call(cgutils.get_or_insert_function(builder.module, fnty, name), args)


def _vec_intrinsic(llvm_name, nargs):
    if nargs == 1:

        @intrinsic
        def op1(typingctx, a):
            def codegen(context, builder, signature, args):
                return _call(builder, llvm_name, args)

            return f8(f8), codegen

        return op1
    if nargs == 2:

        @intrinsic
        def op2(typingctx, a, b):
            def codegen(context, builder, signature, args):
                return _call(builder, llvm_name, args)

            return f8(f8, f8), codegen

        return op2

    @intrinsic
    def op3(typingctx, a, b, c):
        def codegen(context, builder, signature, args):
            return _call(builder, llvm_name, args)

        return f8(f8, f8, f8), codegen

    return op3


_vfma = _vec_intrinsic("llvm.fma.v8f32", 3)
_vmin = _vec_intrinsic("llvm.minnum.v8f32", 2)
_vmax = _vec_intrinsic("llvm.maxnum.v8f32", 2)
_vabs = _vec_intrinsic("llvm.fabs.v8f32", 1)
_vsqrt = _vec_intrinsic("llvm.sqrt.v8f32", 1)
_vfloor = _vec_intrinsic("llvm.floor.v8f32", 1)


def fma(a, b, c):
    """``a * b + c`` (one rounding in the lanes; in float64 the plain expression)."""
    raise NotImplementedError("numba only")


def vmin(a, b):
    raise NotImplementedError("numba only")


def vmax(a, b):
    raise NotImplementedError("numba only")


def vabs(a):
    raise NotImplementedError("numba only")


def vsqrt(a):
    raise NotImplementedError("numba only")


def vfloor(a):
    raise NotImplementedError("numba only")


@overload(fma)
def _ov_fma(a, b, c):
    if a == f8 and b == f8 and c == f8:
        return lambda a, b, c: _vfma(a, b, c)
    if all(isinstance(t, types.Float) for t in (a, b, c)):
        return lambda a, b, c: a * b + c
    return None


@overload(vmin)
def _ov_vmin(a, b):
    if a == f8 and b == f8:
        return lambda a, b: _vmin(a, b)
    if isinstance(a, types.Float) and isinstance(b, types.Float):
        return lambda a, b: min(a, b)
    return None


@overload(vmax)
def _ov_vmax(a, b):
    if a == f8 and b == f8:
        return lambda a, b: _vmax(a, b)
    if isinstance(a, types.Float) and isinstance(b, types.Float):
        return lambda a, b: max(a, b)
    return None


@overload(vabs)
def _ov_vabs(a):
    if a == f8:
        return lambda a: _vabs(a)
    if isinstance(a, types.Float):
        return lambda a: abs(a)
    return None


@overload(vsqrt)
def _ov_vsqrt(a):
    if a == f8:
        return lambda a: _vsqrt(a)
    if isinstance(a, types.Float):
        return lambda a: math.sqrt(a)
    return None


@overload(vfloor)
def _ov_vfloor(a):
    if a == f8:
        return lambda a: _vfloor(a)
    if isinstance(a, types.Float):
        return lambda a: math.floor(a)
    return None


# ------------------------------------------------------------------ masks
def _vec_cmp(pred):
    @intrinsic
    def op(typingctx, a, b):
        sig = m8(f8, f8)

        def codegen(context, builder, signature, args):
            return builder.fcmp_ordered(pred, args[0], args[1])

        return sig, codegen

    return op


for _op, _pred in (
    (operator.lt, "<"),
    (operator.le, "<="),
    (operator.gt, ">"),
    (operator.ge, ">="),
):

    def _make_cmp(impl):
        def ov(a, b):
            if a == f8 and b == f8:
                return lambda a, b: impl(a, b)
            return None

        return ov

    overload(_op)(_make_cmp(_vec_cmp(_pred)))


def _mask_binop(name):
    @intrinsic
    def op(typingctx, a, b):
        sig = m8(m8, m8)

        def codegen(context, builder, signature, args):
            return getattr(builder, name)(args[0], args[1])

        return sig, codegen

    return op


_mand, _mor = _mask_binop("and_"), _mask_binop("or_")
for _op, _impl in ((operator.and_, _mand), (operator.or_, _mor)):

    def _make_m(impl):
        def ov(a, b):
            if a == m8 and b == m8:
                return lambda a, b: impl(a, b)
            return None

        return ov

    overload(_op)(_make_m(_impl))


@intrinsic
def _mnot(typingctx, a):
    sig = m8(m8)

    def codegen(context, builder, signature, args):
        return builder.not_(args[0])

    return sig, codegen


@overload(operator.invert)
def _ov_invert(a):
    if a == m8:
        return lambda a: _mnot(a)
    return None


@intrinsic
def _mask_bits(typingctx, m):
    """The mask as an integer: bit k set when lane k is."""
    sig = types.int64(m8)

    def codegen(context, builder, signature, args):
        bits = builder.bitcast(args[0], ir.IntType(LANES))
        return builder.zext(bits, ir.IntType(64))

    return sig, codegen


@intrinsic
def _bits_mask(typingctx, b):
    """The mask of an integer's low bits (lane k set when bit k is)."""
    sig = m8(types.int64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(builder.trunc(args[0], ir.IntType(LANES)), _MASK)

    return sig, codegen


@intrinsic
def _select(typingctx, m, a, b):
    """Lane by lane: a where the mask is set, else b."""
    sig = f8(m8, f8, f8)

    def codegen(context, builder, signature, args):
        return builder.select(args[0], args[1], args[2])

    return sig, codegen


# ------------------------------------------------------------------ either width
def width(a):
    """Lanes a value of array a's kind holds: LANES for float32 (vectors), 1 for float64."""
    raise NotImplementedError("numba only")


@overload(width)
def _ov_width(a):
    if _is32(a):
        return lambda a: LANES
    if isinstance(a, types.Array):
        return lambda a: 1
    return None


def like(a, x):
    """The scalar x as a value of array a's kind: splat for float32, x itself for float64."""
    raise NotImplementedError("numba only")


@overload(like)
def _ov_like(a, x):
    if _is32(a):
        return lambda a, x: _vsplat(np.float32(x))
    if isinstance(a, types.Array):
        return lambda a, x: np.float64(x)
    return None


#: the mask as an integer: bit k set when lane k is
mask_bits: Any = _mask_bits
#: the mask of an integer's low bits (lane k set when bit k is)
bits_mask: Any = _bits_mask
#: lane by lane: ``select(mask, a, b)`` is a where the mask is set, else b
select: Any = _select

__all__ = [
    "LANES",
    "kernel",
    "unliteral",
    "like",
    "width",
    "bits_mask",
    "f8",
    "fma",
    "lane",
    "load",
    "m8",
    "mask_bits",
    "select",
    "splat",
    "store",
    "vabs",
    "vfloor",
    "vmax",
    "vmin",
    "vsqrt",
]
