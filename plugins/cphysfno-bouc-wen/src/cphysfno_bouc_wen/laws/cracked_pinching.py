"""The pinching story spring with a cracking spring beside it: a trilinear backbone."""

from __future__ import annotations

from typing import Annotated

import numba
import numpy as np
from cphysfno_core.plugin import LawFunctions, per_story
from pydantic import Field

from .bilinear import bilinear_force, bilinear_rate, bilinear_settle
from .common import PerStory, RatioPerStory
from .peak_oriented import PeakOrientedLaw, hysteretic_rate, hysteretic_settle
from .pinching import UNCACHED, PinchingLaw, PinchingLawParams

CRACK_SHARE_LIMIT = 0.95
"""The largest share of the initial stiffness the cracking spring may hold: the pinching
spring keeps at least the rest."""

CrackShare = Annotated[float, Field(ge=0.0, le=CRACK_SHARE_LIMIT)]


class CrackedPinchingLawParams(PinchingLawParams):
    """Parameters of :class:`CrackedPinchingLaw` (scalars or one value per story)."""

    crack_share: CrackShare | tuple[CrackShare, ...] = Field(
        0.3,
        description=f"share r of the initial stiffness the story loses at cracking, 0 to "
        f"{CRACK_SHARE_LIMIT}",
    )
    crack_displacement: PerStory = Field(description="cracking drift u_c, m")
    crack_hysteresis: RatioPerStory = Field(
        0.0,
        description="share h of the cracking spring that is elastic-perfectly-plastic (the "
        "rest nonlinear elastic), 0 to 1",
    )


@numba.njit(**UNCACHED)
def cracked_force(c, v, s):
    """``F = F_p + h r k z_c + (1 - h) r k clip(v, -u_c, u_c)`` (N): the pinching
    spring's force ``s[0]`` and the cracking spring's, ``c = [(1 - r) k, alpha, u_y,
    pinch_x, pinch_y, beta_unload, h r k, 0, u_c, (1 - h) r k]`` (``c[6:9]`` a
    ``bilinear`` spring's of ``alpha = 0``, whose state is ``s[5]``)."""
    return s[0] + bilinear_force(c[6:], v, s[5:]) + c[9] * min(max(v, -c[8]), c[8])


@numba.njit(**UNCACHED)
def cracked_rate(c, v, v_dot, s, out):
    """The pinching spring's rate and the elastic-perfectly-plastic part's."""
    hysteretic_rate(c, v, v_dot, s, out, c[3], c[4], c[5])
    bilinear_rate(c[6:], v, v_dot, s[5:], out[5:])


@numba.njit(**UNCACHED)
def cracked_settle(c, v, s):
    """The pinching spring's settling and the elastic-perfectly-plastic part's."""
    hysteretic_settle(c, v, s, c[3], c[4], c[5])
    bilinear_settle(c[6:], v, s[5:])


class CrackedPinchingLaw(PinchingLaw):
    """The ``pinching`` law beside a cracking spring: a reinforced-concrete story that
    cracks before it yields.

    The story's initial stiffness ``k`` is shared: the cracking spring holds ``r k``
    (``r = crack_share``) up to the cracking drift ``u_c`` and ``r k u_c`` beyond; the
    pinching spring holds ``(1 - r) k`` and follows :class:`PinchingLaw` with ``alpha``,
    ``u_y`` and its pinching and unloading parameters. The backbone is trilinear: ``k`` up
    to ``u_c``, ``(1 - r) k`` up to ``u_y``, then ``alpha (1 - r) k`` (for
    ``u_c < u_y``). The cracking spring is nonlinear elastic (cracks that close as the
    elastic reinforcement pulls the story back: no loop and no residual drift of its
    own) but for a share ``h = crack_hysteresis`` that is elastic-perfectly-plastic (a
    loop in every cycle wider than ``2 u_c``, as plasticity that spreads through a steel
    member before it yields). ``r = 0`` is the ``pinching`` law.

    ``alpha`` is not negative, for the reason :class:`PeakOrientedLaw` gives.
    """

    name = "cracked-pinching"
    Params = CrackedPinchingLawParams
    n_states = PeakOrientedLaw.n_states + 1
    state_names = (
        *PeakOrientedLaw.state_names,
        "displacement z_c of the cracking spring's elastic-perfectly-plastic share, m",
    )

    def coefficients(self, stiffness: np.ndarray) -> np.ndarray:
        """``[d, 10]``: the pinching spring's ``(1 - r) k`` (N/m), ``alpha``, ``u_y`` (m),
        ``pinch_x``, ``pinch_y``, ``beta_unload``; the cracking spring's
        elastic-perfectly-plastic ``h r k`` (N/m), 0 (its post-yield ratio) and ``u_c``
        (m); its nonlinear-elastic ``(1 - h) r k`` (N/m), of each story."""
        d = len(stiffness)
        share = per_story(self.params.crack_share, d, "story_law.crack_share")
        hysteresis = per_story(self.params.crack_hysteresis, d, "story_law.crack_hysteresis")
        cracking = share * np.asarray(stiffness)
        pinching = super().coefficients(stiffness)
        pinching[:, 0] *= 1.0 - share
        u_c = per_story(self.params.crack_displacement, d, "story_law.crack_displacement")
        return np.column_stack(
            [pinching, hysteresis * cracking, np.zeros(d), u_c, (1.0 - hysteresis) * cracking]
        )

    def functions(self) -> LawFunctions:
        return LawFunctions(cracked_force, cracked_rate, cracked_settle)
