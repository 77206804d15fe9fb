"""The pinching story spring with a cracking spring beside it: a trilinear backbone."""

from __future__ import annotations

from typing import Annotated

import numba
import numpy as np
from cphysfno_core.plugin import LawFunctions, per_story
from pydantic import Field

from .bilinear import bilinear_force, bilinear_rate, bilinear_settle
from .common import PerStory
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


@numba.njit(**UNCACHED)
def cracked_force(c, v, s):
    """``F = F_p + r k z_c`` (N): the pinching spring's force ``s[0]`` and the cracking
    spring's, ``c = [(1 - r) k, alpha, u_y, pinch_x, pinch_y, beta_unload, r k, 0, u_c]``
    (the last three a ``bilinear`` spring's of ``alpha = 0``, whose state is ``s[5]``)."""
    return s[0] + bilinear_force(c[6:], v, s[5:])


@numba.njit(**UNCACHED)
def cracked_rate(c, v, v_dot, s, out):
    """The pinching spring's rate and the cracking spring's."""
    hysteretic_rate(c, v, v_dot, s, out, c[3], c[4], c[5])
    bilinear_rate(c[6:], v, v_dot, s[5:], out[5:])


@numba.njit(**UNCACHED)
def cracked_settle(c, v, s):
    """The pinching spring's settling and the cracking spring's."""
    hysteretic_settle(c, v, s, c[3], c[4], c[5])
    bilinear_settle(c[6:], v, s[5:])


class CrackedPinchingLaw(PinchingLaw):
    """The ``pinching`` law beside an elastic-perfectly-plastic cracking spring: a
    reinforced-concrete story that cracks before it yields.

    The story's initial stiffness ``k`` is shared: the cracking spring holds ``r k``
    (``r = crack_share``) up to the cracking drift ``u_c`` and then carries ``r k u_c``
    at most (it dissipates in every cycle wider than ``2 u_c``, as cracks that open and
    close do); the pinching spring holds ``(1 - r) k`` and follows :class:`PinchingLaw`
    with ``alpha``, ``u_y`` and its pinching and unloading parameters. The backbone is
    trilinear: ``k`` up to ``u_c``, ``(1 - r) k`` up to ``u_y``, then
    ``alpha (1 - r) k`` (for ``u_c < u_y``). ``r = 0`` is the ``pinching`` law.

    ``alpha`` is not negative, for the reason :class:`PeakOrientedLaw` gives.
    """

    name = "cracked-pinching"
    Params = CrackedPinchingLawParams
    n_states = PeakOrientedLaw.n_states + 1
    state_names = (*PeakOrientedLaw.state_names, "cracking spring's displacement z_c, m")

    def coefficients(self, stiffness: np.ndarray) -> np.ndarray:
        """``[d, 9]``: the pinching spring's ``(1 - r) k`` (N/m), ``alpha``, ``u_y`` (m),
        ``pinch_x``, ``pinch_y``, ``beta_unload``, and the cracking spring's ``r k`` (N/m),
        0 (its post-yield ratio) and ``u_c`` (m) of each story."""
        d = len(stiffness)
        share = per_story(self.params.crack_share, d, "story_law.crack_share")
        pinching = super().coefficients(stiffness)
        pinching[:, 0] *= 1.0 - share
        cracking = per_story(self.params.crack_displacement, d, "story_law.crack_displacement")
        return np.column_stack([pinching, share * np.asarray(stiffness), np.zeros(d), cracking])

    def functions(self) -> LawFunctions:
        return LawFunctions(cracked_force, cracked_rate, cracked_settle)
