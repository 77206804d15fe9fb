"""Building blocks of the compiled (numba) integrators.

- :data:`JIT` — the compilation options every kernel uses: cached on disk (so compilation
  is paid once per machine), no GIL (so threads run kernels side by side), IEEE semantics
  for NaN and infinity (divergence stays detectable) but free reassociation and FMA.
- :func:`local_array` — a small array on the stack of the compiled function. Indexed with
  compile-time constants it lives in registers, which is what lets LLVM vectorise a loop
  whose body works on a whole record's state.
- :func:`size_marker`, :func:`whole_power` — sizes passed as tuple lengths, which makes them
  part of a kernel's argument types (compile-time constants).
- :func:`bouc_wen_rate`, :func:`hysteretic_power` — the Bouc-Wen law of one story.
"""

from __future__ import annotations

import math

import numba
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

JIT = {
    "cache": True,
    "nogil": True,
    "error_model": "numpy",
    "fastmath": {"nsz", "arcp", "contract", "afn", "reassoc"},
}


@intrinsic
def local_array(typingctx, shape, dtype):
    """``numpy.empty(shape, dtype)`` on the stack of the calling compiled function.

    ``shape`` is a tuple whose entries are compile-time sizes: integer constants (module
    globals, literals) or tuples, which stand for their length. The array is C-contiguous
    and lives until the calling function returns.
    """
    if not isinstance(shape, types.BaseTuple):
        return None
    sizes = []
    for size in shape.types:
        if isinstance(size, types.IntegerLiteral):
            sizes.append(size.literal_value)
        elif isinstance(size, types.BaseTuple):
            sizes.append(len(size))
        else:
            return None
    item = dtype.dtype if isinstance(dtype, types.DType | types.NumberClass) else None
    if item is None:
        return None
    array_type = types.Array(item, len(sizes), "C")

    def codegen(context, builder, signature, args):
        element = context.get_value_type(item)
        itemsize = context.get_abi_sizeof(element)
        data = cgutils.alloca_once(builder, element, size=max(1, math.prod(sizes)))
        strides = [itemsize * math.prod(sizes[axis + 1 :]) for axis in range(len(sizes))]
        intp = context.get_value_type(types.intp)
        array = make_array(array_type)(context, builder)
        populate_array(
            array,
            data=data,
            shape=[intp(size) for size in sizes],
            strides=[intp(stride) for stride in strides],
            itemsize=intp(itemsize),
            meminfo=None,
        )
        return array._getvalue()

    return array_type(shape, dtype), codegen


def size_marker(size: int) -> tuple[int, ...]:
    """A tuple of length ``size``: passed to a kernel, its length is part of the argument
    types, hence a compile-time constant (loops over it unroll, :func:`local_array` takes it
    as a size), and each size gets its own compiled version."""
    return (0,) * int(size)


def whole_power(power: float) -> tuple[int, ...]:
    """:func:`size_marker` of ``power = n - 1`` when it is a whole number > 0, else empty
    (the kernels then use ``pow``)."""
    return size_marker(power) if power.is_integer() and power > 0 else ()


@numba.njit(inline="always", **JIT)
def hysteretic_power(magnitude, power, whole_power):
    """``|h|^(n-1)`` from ``magnitude = |h|`` (m) and ``power = n - 1``.

    ``whole_power`` is :func:`size_marker` of ``n - 1`` when ``n > 1`` is a whole number
    (the power is then that many multiplications), else empty (``pow``).
    """
    if len(whole_power) > 0:
        scaled = magnitude
        for _ in range(len(whole_power) - 1):
            scaled *= magnitude
        return scaled
    return magnitude**power


@numba.njit(inline="always", **JIT)
def bouc_wen_rate(drift_rate, hysteretic, a, delta, zeta, power, whole_power):
    """``h' = v' (A - zeta |h|^n) - delta |v'| |h|^(n-1) h`` of one story, m/s.

    Args:
        drift_rate: ``v'`` in m/s.
        hysteretic: ``h`` in m.
        a, delta, zeta: Bouc-Wen A, delta and zeta (1/m^n).
        power, whole_power: ``n - 1``, as for :func:`hysteretic_power`.
    """
    magnitude = abs(hysteretic)
    scaled = hysteretic_power(magnitude, power, whole_power)
    return drift_rate * (a - zeta * scaled * magnitude) - delta * abs(drift_rate) * scaled * (
        hysteretic
    )
