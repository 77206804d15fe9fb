"""Checks and blocking shared by the refiners."""

from __future__ import annotations

import numpy as np

from cphysfno_core import InputError
from cphysfno_core.signals import check_finite

BLOCK_ELEMENTS = 2**18
"""Elements (float64) of the record blocks that refiners and the finiteness check work on,
so that their temporaries stay a few MiB whatever the number of records."""


def as_responses(who: str, **arrays: np.ndarray) -> list[np.ndarray]:
    """The arrays as float64, or :class:`InputError` unless all are ``[n, T, dof]`` alike."""
    converted = {name: np.asarray(a, dtype=np.float64) for name, a in arrays.items()}
    shapes = ", ".join(f"{name} {a.shape}" for name, a in converted.items())
    first = next(iter(converted.values()))
    if first.ndim != 3 or any(a.shape != first.shape for a in converted.values()):
        raise InputError(f"{who}: expected arrays of one shape [n, T, dof], got {shapes}")
    for name, a in converted.items():
        for rows in record_blocks(a.shape):
            if not np.isfinite(a[rows]).all():
                check_finite(a, name)
    return list(converted.values())


def record_blocks(shape: tuple[int, ...]) -> list[slice]:
    """Slices of whole records of about :data:`BLOCK_ELEMENTS` elements, covering ``shape[0]``."""
    per_record = max(1, int(np.prod(shape[1:])))
    step = max(1, BLOCK_ELEMENTS // per_record)
    return [slice(start, start + step) for start in range(0, shape[0], step)]
