"""The peak-oriented (Clough) story spring: stiffness that degrades with the peak drift."""

from __future__ import annotations

import numba
from cphysfno_core.plugin import LawFunctions, Params
from pydantic import Field

from .common import LAW_JIT, PerStory, RatioPerStory
from .yielding import YieldingLaw


class PeakOrientedLawParams(Params):
    """Parameters of :class:`PeakOrientedLaw` (scalars or one value per story)."""

    alpha: RatioPerStory = Field(0.05, description="post-yield to initial stiffness ratio, 0 to 1")
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
def unloading_stiffness(c, s, side, beta):
    """Unloading stiffness (N/m) from a force on ``side`` (+1 or -1): ``k (u_y / d)^beta``
    with ``d`` the largest drift (m) reached on that side (at least ``u_y``); ``beta = 0``
    gives ``k`` (as does a side not yet past yield, without a power)."""
    past = s[1] if side > 0 else s[2]
    if past == 0.0 or beta == 0.0:
        return c[0]
    u_y = c[2]
    return c[0] * (u_y / (u_y + past)) ** beta


@numba.njit(**LAW_JIT)
def pinched_target(c, v, s, direction, pinch_x, pinch_y, beta):
    """Force (N) of the branch that reloading follows at drift ``v`` (m) in ``direction``
    (+1 or -1), and that branch's slope (N/m).

    Past the peak the branch is the backbone. Before it, two lines: from the last zero
    crossing to the pinch point, then to the peak (only the second where the pinch point
    is not past the crossing). The pinch point has ``pinch_y`` times the peak force and
    lies ``pinch_x`` of the way from the crossing to the drift where the unloading line
    from the peak (stiffness :func:`unloading_stiffness` of this side) has that force, as
    in OpenSees' ``Hysteretic``; ``pinch_x = pinch_y = 1`` puts it on the peak. A line
    steeper than the unloading stiffness turns about its end to that stiffness."""
    peak = direction * (c[2] + (s[1] if direction > 0 else s[2]))
    crossing = s[3] if direction > 0 else s[4]
    top = backbone(c, peak)
    if direction * (v - peak) >= 0.0:
        return backbone(c, v), c[1] * c[0]
    stiffness = unloading_stiffness(c, s, direction, beta)
    toward = peak - (1.0 - pinch_y) * top / stiffness
    pinch = toward - (1.0 - pinch_x) * (toward - crossing)
    height = pinch_y * top
    if direction * (v - pinch) >= 0.0 or direction * (pinch - crossing) <= 0.0:
        span, rise, end, level = peak - pinch, top - height, peak, top
    else:
        span, rise, end, level = pinch - crossing, height, pinch, height
    if direction * span <= 0.0:
        return level, stiffness
    slope = min(rise / span, stiffness)
    return level + slope * (v - end), slope


@numba.njit(**LAW_JIT)
def reload_target(c, v, s, direction):
    """Force (N) of the branch that reloading follows at drift ``v`` in ``direction``
    (+1 or -1), and that branch's slope (N/m): the line from the last zero crossing to the
    peak, or the backbone past the peak."""
    return pinched_target(c, v, s, direction, 1.0, 1.0, 0.0)


@numba.njit(**LAW_JIT)
def hysteretic_rate(c, v, v_dot, s, out, pinch_x, pinch_y, beta):
    """``F' = k_t v'`` with the tangent of the branch the story is on: unloading toward
    zero force at the unloading stiffness of the side the force is on, reloading below
    :func:`pinched_target` at the unloading stiffness of the side it heads for, else the
    target's slope. Peaks and zero crossings move in :func:`hysteretic_settle`."""
    force = s[0]
    for m in range(1, 5):
        out[m] = 0.0
    direction = 1.0 if v_dot >= 0.0 else -1.0
    if direction * force < 0.0:
        out[0] = unloading_stiffness(c, s, -direction, beta) * v_dot
        return
    target, slope = pinched_target(c, v, s, direction, pinch_x, pinch_y, beta)
    if direction * (target - force) > 1e-9 * c[0] * c[2]:
        out[0] = unloading_stiffness(c, s, direction, beta) * v_dot
    else:
        out[0] = slope * v_dot


@numba.njit(**LAW_JIT)
def hysteretic_settle(c, v, s, pinch_x, pinch_y, beta):
    """Keep the force inside the reloading branches, put it on the backbone past the
    peak (where reloading at the unloading stiffness has not reached the peak force, the
    force steps onto the backbone, as in OpenSees' ``Hysteretic``), move a peak that the
    story has passed, and follow the zero crossing of the unloading line."""
    k, u_y = c[0], c[2]
    tolerance = 1e-9 * k * u_y
    for direction in (1.0, -1.0):
        if direction * s[0] >= 0.0:
            target, _ = pinched_target(c, v, s, direction, pinch_x, pinch_y, beta)
            beyond = direction * v - (u_y + (s[1] if direction > 0 else s[2]))
            if direction * (s[0] - target) > 0.0 or (
                beyond >= 0.0 and direction * (target - s[0]) > tolerance
            ):
                s[0] = target
            if beyond > 0.0 and abs(s[0] - backbone(c, v)) <= tolerance:
                if direction > 0:
                    s[1] = v - u_y
                else:
                    s[2] = -v - u_y
        else:
            crossing = v - s[0] / unloading_stiffness(c, s, -direction, beta)
            if direction > 0:
                s[3] = crossing
            else:
                s[4] = crossing


@numba.njit(**LAW_JIT)
def peak_oriented_rate(c, v, v_dot, s, out):
    """:func:`hysteretic_rate` without pinching, unloading at ``k`` (state in
    :class:`PeakOrientedLaw`)."""
    hysteretic_rate(c, v, v_dot, s, out, 1.0, 1.0, 0.0)


@numba.njit(**LAW_JIT)
def peak_oriented_settle(c, v, s):
    """:func:`hysteretic_settle` without pinching, unloading at ``k``."""
    hysteretic_settle(c, v, s, 1.0, 1.0, 0.0)


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

    ``alpha`` is not negative here, unlike ``bilinear`` and ``bouc-wen``: the rules tell
    unloading from loading by the sign of the force and aim reloading at the backbone's
    force at the peak, while a falling backbone's force changes sign at
    ``u_y (1 - 1 / alpha)``; past that drift a peak's force would be of the other sign and
    its loop undefined. A story that softens past yield takes one of those two laws.
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
