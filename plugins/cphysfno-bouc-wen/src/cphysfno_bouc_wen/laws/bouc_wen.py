"""The Bouc-Wen story spring (the law of the paper's Example 1 building)."""

from __future__ import annotations

import numba
import numpy as np
from cphysfno_core.plugin import LawFunctions, Params, per_story
from pydantic import Field

from .common import LAW_JIT, ExponentPerStory, PerStory, PostYieldRatioPerStory, no_settling
from .yielding import YieldingLaw


class BoucWenLawParams(Params):
    """Parameters of :class:`BoucWenLaw` (scalars or one value per story)."""

    alpha: PostYieldRatioPerStory = Field(
        0.1,
        description="post-yield to initial stiffness ratio, -0.5 to 1 (negative: softening "
        "past yield, such as P-Delta)",
    )
    exponent: ExponentPerStory = Field(3.0, description="smoothness exponent n, 1 to 50")
    A: PerStory = Field(1.0, description="amplitude A")
    yield_displacement: PerStory = Field(0.01, description="yield drift u_y, m")
    beta: PerStory | None = Field(None, description="beta, 1/m^n (default 1/(2 u_y^n))")
    gamma: PerStory | None = Field(None, description="gamma, 1/m^n (default 1/(2 u_y^n))")


@numba.njit(**LAW_JIT)
def bouc_wen_force(c, v, s):
    """``F = k [alpha v + (1 - alpha) h]`` (N), ``c = [k, alpha, A, beta, gamma, n]``."""
    return c[0] * (c[1] * v + (1.0 - c[1]) * s[0])


@numba.njit(**LAW_JIT)
def bouc_wen_law_rate(c, v, v_dot, s, out):
    """``h' = A v' - beta |v'| |h|^(n-1) h - gamma v' |h|^n`` (m/s); a whole exponent up
    to 9 by multiplication."""
    h = s[0]
    magnitude = abs(h)
    exponent = c[5] - 1.0
    if exponent == int(exponent) and exponent <= 8.0:
        power = 1.0
        for _ in range(int(exponent)):
            power *= magnitude
    else:
        power = magnitude**exponent
    out[0] = v_dot * (c[2] - c[4] * power * magnitude) - c[3] * abs(v_dot) * power * h


class BoucWenLaw(YieldingLaw):
    """Bouc-Wen smooth hysteresis: ``F = k [alpha v + (1 - alpha) h]``, ``h`` from Bouc-Wen's
    equation.

    ``h' = A v' - beta |v'| |h|^(n-1) h - gamma v' |h|^n``.

    ``beta = gamma = 1/(2 u_y^n)`` unless given: with ``A = 1`` the hysteretic part then
    saturates at ``|h| = u_y``, the formulation of the paper's Example 1 building.

    A negative ``alpha`` (down to :data:`~.common.SOFTENING_LIMIT`) is a softening past
    yield, such as P-Delta: ``h`` depends on neither ``k`` nor ``alpha``, so a story of
    this law with the geometric stiffness ``-k_g v`` of its gravity load (``k_g = P / H``
    in N/m, the load P in N over the story height H in m) is exactly this law with
    ``k - k_g`` and ``(alpha k - k_g) / (k - k_g)``, the rest unchanged.
    """

    name = "bouc-wen"
    Params = BoucWenLawParams
    n_states = 1
    state_names = ("hysteretic displacement h, m",)

    def hysteretic_bound(self, n_stories: int) -> np.ndarray:
        """``[d]`` the magnitude (m) ``h`` saturates at, ``(A / (beta + gamma))^(1/n)``
        (``inf`` where ``beta + gamma <= 0``: ``h`` grows without bound)."""
        c = self.coefficients(np.ones(n_stories))
        total = c[:, 3] + c[:, 4]
        bound = np.full(n_stories, np.inf)
        positive = total > 0.0
        bound[positive] = (c[positive, 2] / total[positive]) ** (1.0 / c[positive, 5])
        return bound

    def coefficients(self, stiffness: np.ndarray) -> np.ndarray:
        """``[d, 6]``: ``k`` (N/m), ``alpha``, ``A``, ``beta``, ``gamma`` (1/m^n), ``n``."""
        d = len(stiffness)
        p = self.params
        exponent = per_story(p.exponent, d, "story_law.exponent")
        default = 0.5 / self.yield_drift(d) ** exponent
        beta = default if p.beta is None else per_story(p.beta, d, "story_law.beta")
        gamma = default if p.gamma is None else per_story(p.gamma, d, "story_law.gamma")
        return np.column_stack(
            [
                np.asarray(stiffness, dtype=np.float64),
                per_story(p.alpha, d, "story_law.alpha"),
                per_story(p.A, d, "story_law.A"),
                beta,
                gamma,
                exponent,
            ]
        )

    def functions(self) -> LawFunctions:
        return LawFunctions(bouc_wen_force, bouc_wen_law_rate, no_settling)

    def uniform(self) -> bool:
        """Whether every parameter is one scalar for all stories."""
        return all(not isinstance(value, tuple) for value in self.params.model_dump().values())
