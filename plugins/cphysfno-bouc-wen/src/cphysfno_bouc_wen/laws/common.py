"""What the built-in laws share: the compile options and parameter types."""

from __future__ import annotations

from typing import Annotated

import numba
from pydantic import Field

LAW_JIT = {"cache": True, "nogil": True, "inline": "always", "error_model": "numpy"}
"""Options of every law function: cached on disk, free of the GIL, inlined into the
integrator that calls it."""

PositiveFloat = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]
"""A finite float > 0."""

Ratio = Annotated[float, Field(ge=0.0, le=1.0)]
"""A float in [0, 1]."""

PerStory = PositiveFloat | tuple[PositiveFloat, ...]
"""A positive value for every story, or one per story (bottom story first)."""

RatioPerStory = Ratio | tuple[Ratio, ...]
"""A ratio in [0, 1] for every story, or one per story."""

SOFTENING_LIMIT = -0.5
"""The lowest post-yield stiffness ratio ``alpha`` of a law that may soften past yield:
the P-Delta of a perfectly plastic story (``alpha = -theta / (1 - theta)``) whose
stability coefficient ``theta = P / (k H)`` (gravity load P in N over the story's initial
stiffness k in N/m times its height H in m) is 1/3, beyond the 0.25 that ASCE 7 allows
in design."""

PostYieldRatio = Annotated[float, Field(ge=SOFTENING_LIMIT, le=1.0)]
"""A post-yield stiffness ratio in [:data:`SOFTENING_LIMIT`, 1]: negative where the story
softens past yield."""

PostYieldRatioPerStory = PostYieldRatio | tuple[PostYieldRatio, ...]
"""A post-yield stiffness ratio for every story, or one per story."""

Exponent = Annotated[float, Field(ge=1.0, le=50.0)]
"""A smoothness exponent in [1, 50]."""

ExponentPerStory = Exponent | tuple[Exponent, ...]
"""An exponent for every story, or one per story."""


@numba.njit(**LAW_JIT)
def no_settling(c, v, s):
    """The ``settle`` of a smooth law: nothing to correct."""
