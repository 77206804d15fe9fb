"""The bilinear story spring with kinematic hardening."""

from __future__ import annotations

import numba
from cphysfno_core.plugin import LawFunctions, Params
from pydantic import Field

from .common import LAW_JIT, PerStory, PostYieldRatioPerStory
from .yielding import YieldingLaw


class BilinearLawParams(Params):
    """Parameters of :class:`BilinearLaw` (scalars or one value per story)."""

    alpha: PostYieldRatioPerStory = Field(
        0.1,
        description="post-yield to initial stiffness ratio, -0.5 to 1 (negative: softening "
        "past yield, such as P-Delta)",
    )
    yield_displacement: PerStory = Field(description="yield drift u_y, m")


@numba.njit(**LAW_JIT)
def bilinear_force(c, v, s):
    """``F = k [alpha v + (1 - alpha) z]`` (N), ``c = [k, alpha, u_y]``, ``s = [z]`` (m)."""
    return c[0] * (c[1] * v + (1.0 - c[1]) * s[0])


@numba.njit(**LAW_JIT)
def bilinear_rate(c, v, v_dot, s, out):
    """``z' = v'`` inside the yield range or moving back into it, else 0 (m/s)."""
    z = s[0]
    if abs(z) >= c[2] and z * v_dot > 0.0:
        out[0] = 0.0
    else:
        out[0] = v_dot


@numba.njit(**LAW_JIT)
def bilinear_settle(c, v, s):
    """Return ``z`` to ``[-u_y, u_y]`` when a step has carried it past."""
    s[0] = min(max(s[0], -c[2]), c[2])


class BilinearLaw(YieldingLaw):
    """Elastic-perfectly-plastic spring in parallel with ``alpha k`` (kinematic hardening).

    ``F = k [alpha v + (1 - alpha) z]`` with ``|z| <= u_y`` the elastic-perfectly-plastic
    displacement: the initial stiffness is ``k``, the story yields at ``v = u_y`` with
    ``F = k u_y`` and then stiffens at ``alpha k``; unloading is elastic (``k``), and the
    elastic range stays ``2 u_y`` wide wherever it has moved (OpenSees' ``Steel01`` with
    ``b = alpha`` and no isotropic hardening).

    A negative ``alpha`` (down to :data:`~.common.SOFTENING_LIMIT`) is a softening past
    yield, such as P-Delta: a story of this law (``k``, ``alpha``, ``u_y``) with the
    geometric stiffness ``-k_g v`` of its gravity load (``k_g = P / H`` in N/m, the load P
    in N over the story height H in m) is exactly this law with ``k - k_g``,
    ``(alpha k - k_g) / (k - k_g)`` and the same ``u_y``. Its force then falls past yield
    and changes sign at ``v = u_y (1 - 1 / alpha)``: past that drift the story has no
    strength left.
    """

    name = "bilinear"
    Params = BilinearLawParams
    n_states = 1
    state_names = ("elastic-perfectly-plastic displacement z, m",)

    def functions(self) -> LawFunctions:
        return LawFunctions(bilinear_force, bilinear_rate, bilinear_settle)
