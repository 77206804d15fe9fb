"""The pinching story spring: peak-oriented reloading through a pinch point, and unloading
stiffness that degrades with the largest drift."""

from __future__ import annotations

import numba
import numpy as np
from cphysfno_core.plugin import LawFunctions, Params, per_story
from pydantic import Field

from .common import LAW_JIT, PerStory, RatioPerStory
from .peak_oriented import (
    PeakOrientedLaw,
    hysteretic_rate,
    hysteretic_settle,
    peak_oriented_force,
)
from .yielding import YieldingLaw

UNCACHED = {**LAW_JIT, "cache": False}
"""The options of this law's functions: their bodies are compiled from peak_oriented.py,
whose edits a cache on disk keyed on this file would not see."""


class PinchingLawParams(Params):
    """Parameters of :class:`PinchingLaw` (scalars or one value per story)."""

    alpha: RatioPerStory = Field(0.05, description="post-yield to initial stiffness ratio, 0 to 1")
    yield_displacement: PerStory = Field(description="yield drift u_y, m")
    pinch_x: RatioPerStory = Field(
        0.8,
        description="where the pinch point lies between the zero crossing (0) and the "
        "unloading line from the peak (1)",
    )
    pinch_y: RatioPerStory = Field(0.2, description="pinch-point force over the peak force")
    beta_unload: RatioPerStory = Field(
        0.0, description="unloading stiffness k (u_y / largest drift)^beta_unload; 0: k"
    )


@numba.njit(**UNCACHED)
def pinching_rate(c, v, v_dot, s, out):
    """``F' = k_t v'`` on the branch the story is on, ``c = [k, alpha, u_y, pinch_x,
    pinch_y, beta_unload]`` (state in :class:`PinchingLaw`)."""
    hysteretic_rate(c, v, v_dot, s, out, c[3], c[4], c[5])


@numba.njit(**UNCACHED)
def pinching_settle(c, v, s):
    """Clamp the force to the pinched reloading branches, move the peaks, follow the zero
    crossings of the degraded unloading lines."""
    hysteretic_settle(c, v, s, c[3], c[4], c[5])


class PinchingLaw(YieldingLaw):
    """Peak-oriented hysteresis with pinching and degrading unloading stiffness: the
    reinforced-concrete loop of OpenSees' ``Hysteretic`` material without damage.

    A bilinear backbone (initial stiffness ``k``, yield at ``u_y``, then ``alpha k``).
    Unloading from a force on one side runs at ``k_u = k (u_y / d)^beta_unload``, ``d``
    the largest drift (m) reached on that side (at least ``u_y``). Once the force has
    changed sign, reloading first heads for the pinch point, at ``pinch_y`` times the
    backbone force ``F_p`` of the peak (the largest drift ``d_p`` reached in that
    direction), then for the peak; past it, the backbone. The pinch point's drift is
    ``x_0 + pinch_x (x_1 - x_0)``, ``x_0`` the drift of the last zero crossing of the force
    and ``x_1 = d_p - (1 - pinch_y) F_p / k_u`` the drift at which the unloading line from
    the peak has the pinch force (OpenSees' rule). Reloading from a partial unloading runs
    at ``k_u`` until it meets that branch. ``pinch_x = pinch_y = 1`` and
    ``beta_unload = 0`` give the ``peak-oriented`` law.

    OpenSees' ``Hysteretic`` (``pinchX``, ``pinchY``, ``damage1 = damage2 = 0``,
    ``beta``) follows the same loops once the story has passed ``u_y`` both ways, steps
    onto the backbone included (reloading at ``k_u`` that reaches the peak drift below the
    peak force). Before that it takes its backbone at the largest drift seen that way even
    below yield, where this law aims at the yield point; and with ``beta`` near 1, where a
    force keeps its sign past the other side's last zero crossing, it sets the force to
    zero, where this law keeps it on its branch.

    ``alpha`` is not negative, for the reason :class:`PeakOrientedLaw` gives.
    """

    name = "pinching"
    Params = PinchingLawParams
    n_states = PeakOrientedLaw.n_states  # the same state, read through a pinch point
    state_names = PeakOrientedLaw.state_names

    def coefficients(self, stiffness: np.ndarray) -> np.ndarray:
        """``[d, 6]``: ``k`` (N/m), ``alpha``, ``u_y`` (m), ``pinch_x``, ``pinch_y`` and
        ``beta_unload`` of each story."""
        d = len(stiffness)
        p = self.params
        return np.column_stack(
            [
                super().coefficients(stiffness),
                per_story(p.pinch_x, d, "story_law.pinch_x"),
                per_story(p.pinch_y, d, "story_law.pinch_y"),
                per_story(p.beta_unload, d, "story_law.beta_unload"),
            ]
        )

    def functions(self) -> LawFunctions:
        return LawFunctions(peak_oriented_force, pinching_rate, pinching_settle)
