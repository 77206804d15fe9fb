"""The peak-oriented (Clough) story spring: stiffness that degrades with the peak drift."""

from __future__ import annotations

import numba
from cphysfno_core import LawFunctions, Params
from pydantic import Field

from .common import LAW_JIT, PerStory, RatioPerStory
from .yielding import YieldingLaw


class PeakOrientedLawParams(Params):
    """Parameters of :class:`PeakOrientedLaw` (scalars or one value per story)."""

    alpha: RatioPerStory = Field(0.05, description="post-yield to initial stiffness ratio")
    yield_displacement: PerStory = Field(description="yield drift u_y, m")


@numba.njit(**LAW_JIT)
def backbone(c, v):
    """Bilinear backbone force (N) at a drift ``v`` (m) beyond yield, ``c = [k, alpha, u_y]``."""
    k, alpha, u_y = c[0], c[1], c[2]
    if v >= 0.0:
        return k * u_y + alpha * k * (v - u_y)
    return -k * u_y + alpha * k * (v + u_y)


@numba.njit(**LAW_JIT)
def peak_oriented_force(c, v, s):
    """The story shear ``F = s[0]`` (N): the law carries its force as state."""
    return s[0]


@numba.njit(**LAW_JIT)
def reload_target(c, v, s, direction):
    """Force (N) of the branch that reloading follows at drift ``v`` in ``direction``
    (+1 or -1), and that branch's slope (N/m): the line from the last zero crossing to the
    peak, or the backbone past the peak."""
    k, alpha = c[0], c[1]
    peak = direction * (c[2] + (s[1] if direction > 0 else s[2]))
    crossing = s[3] if direction > 0 else s[4]
    top = backbone(c, peak)
    if direction * (v - peak) >= 0.0:
        return backbone(c, v), alpha * k
    span = peak - crossing
    if direction * span <= 0.0:
        return top, k
    slope = min(top / span, k)
    return top + slope * (v - peak), slope


@numba.njit(**LAW_JIT)
def peak_oriented_rate(c, v, v_dot, s, out):
    """``F' = k_t v'`` with the tangent of the branch the story is on (state in
    :class:`PeakOrientedLaw`); peaks and zero crossings move in :func:`peak_oriented_settle`."""
    k = c[0]
    force = s[0]
    for m in range(1, 5):
        out[m] = 0.0
    direction = 1.0 if v_dot >= 0.0 else -1.0
    if direction * force < 0.0:
        out[0] = k * v_dot
        return
    target, slope = reload_target(c, v, s, direction)
    if direction * (target - force) > 1e-9 * k * c[2]:
        out[0] = k * v_dot
    else:
        out[0] = slope * v_dot


@numba.njit(**LAW_JIT)
def peak_oriented_settle(c, v, s):
    """Keep the force inside the reloading branches, move a peak that the story has
    passed on the backbone, and follow the zero crossing of the elastic unloading line."""
    k, u_y = c[0], c[2]
    for direction in (1.0, -1.0):
        if direction * s[0] >= 0.0:
            target, _ = reload_target(c, v, s, direction)
            if direction * (s[0] - target) > 0.0:
                s[0] = target
            if (
                direction * v > u_y + (s[1] if direction > 0 else s[2])
                and abs(s[0] - backbone(c, v)) <= 1e-9 * k * u_y
            ):
                if direction > 0:
                    s[1] = v - u_y
                else:
                    s[2] = -v - u_y
        else:
            crossing = v - s[0] / k
            if direction > 0:
                s[3] = crossing
            else:
                s[4] = crossing


class PeakOrientedLaw(YieldingLaw):
    """Clough's peak-oriented hysteresis: reloading aims at the largest drift seen so far.

    (Clough and Johnston 1966.) Used for RC and steel members whose reloading stiffness
    degrades with the deformation they have seen.

    A bilinear backbone (initial stiffness ``k``, yield at ``u_y``, then ``alpha k``);
    unloading at ``k``; once the force has changed sign, reloading aims at the largest
    drift reached so far in that direction (at least ``u_y``) on the backbone, so every
    excursion past yield lowers the reloading stiffness. No strength deterioration and no
    pinching: OpenSees' ``Hysteretic`` material with ``pinchX = pinchY = 1``, no damage
    and ``beta = 0`` follows the same loops.
    """

    name = "peak-oriented"
    Params = PeakOrientedLawParams
    n_states = 5
    state_names = (
        "story shear F, N",
        "largest positive drift past yield p+, m",
        "largest negative drift past yield p-, m",
        "drift at the last upward zero crossing of the force, m",
        "drift at the last downward zero crossing of the force, m",
    )

    def functions(self) -> LawFunctions:
        return LawFunctions(peak_oriented_force, peak_oriented_rate, peak_oriented_settle)
