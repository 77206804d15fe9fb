"""The linear elastic story spring."""

from __future__ import annotations

import numba
import numpy as np
from cphysfno_core.plugin import LawFunctions, Params, StoryLaw

from .common import LAW_JIT, no_settling


class LinearLawParams(Params):
    """The linear law has no parameters: its stiffness is the story's."""


@numba.njit(**LAW_JIT)
def linear_force(c, v, s):
    """``F = k v`` (N) with ``c = [k]`` (N/m) and the drift ``v`` (m)."""
    return c[0] * v


@numba.njit(**LAW_JIT)
def linear_rate(c, v, v_dot, s, out):
    """No state."""


class LinearLaw(StoryLaw):
    """``F = k v``: the story stays elastic at its initial stiffness."""

    name = "linear"
    Params = LinearLawParams

    def coefficients(self, stiffness: np.ndarray) -> np.ndarray:
        """``[d, 1]``: the stiffness k of each story, N/m."""
        return np.asarray(stiffness, dtype=np.float64).reshape(-1, 1).copy()

    def functions(self) -> LawFunctions:
        return LawFunctions(linear_force, linear_rate, no_settling)
