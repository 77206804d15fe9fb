"""The compiled state determination of force-based columns, as OpenSees' ``forceBeamColumn``
does it: the iterative method of Spacone, Filippou and Taucer with its energy tolerance
(or one iteration per Newton iteration of the structure, Neuenhofer and Filippou's
non-iterative form), the fibres of each section evaluated from their committed states, and
the commit and revert of every column's state (see :class:`.columns.ColumnState`).
"""

from __future__ import annotations

import numba
import numpy as np

from . import concrete04, steel02
from .section import add_group, invert, invert3, symmetrise

ELEMENT_TOLERANCE = 1e-12
"""OpenSees' default energy tolerance of the element state determination, J."""
COMPATIBILITY_TOLERANCE = 1e-4
"""Energy of its last correction, J, below which a column that takes one iteration per
Newton iteration counts as converged (its section forces are MN and MN m); what is left
is carried into the next iteration or step, as in Neuenhofer and Filippou's
non-iterative form. From 1e-9 J to 1e-4 J the Newton iterations per step fall from 2.5
to 2.26 on the bridge's records, and a strong record stays 9e-5 from OpenSees."""
ELEMENT_ITERATIONS = 50
"""Element iterations before the state determination gives up."""
ROW = (0, 1, 1, 2, 2)
"""The section force that each of the basic forces ``q0 .. q4`` enters."""


@numba.njit(cache=True, inline="always")
def _section(fibres, materials, committed, c, i, e, force, tangent):
    """Trial forces and tangent of section ``i`` of column ``c`` at deformations ``e``:
    fibres evaluated from the buffer ``committed`` of ``materials``, their trial states
    written to the other one."""
    force[:] = 0.0
    tangent[:, :] = 0.0
    other = 1 - committed
    core, cover, bars = materials
    p, y, z, a = fibres[0], fibres[1], fibres[2], fibres[3]
    add_group(
        concrete04.trial, p, y, z, a, core[committed, c, i], core[other, c, i], e, force, tangent
    )
    p, y, z, a = fibres[4], fibres[5], fibres[6], fibres[7]
    add_group(
        concrete04.trial, p, y, z, a, cover[committed, c, i], cover[other, c, i], e, force,
        tangent,
    )  # fmt: skip
    p, y, z, a = fibres[8], fibres[9], fibres[10], fibres[11]
    add_group(
        steel02.trial, p, y, z, a, bars[committed, c, i], bars[other, c, i], e, force, tangent
    )
    symmetrise(tangent)


@numba.njit(cache=True)
def column_scratch():
    """Work arrays for :func:`update_column`, to allocate once for many calls."""
    return (
        np.empty(6), np.empty(6), np.empty(6), np.empty(5), np.empty(3), np.empty(3),
        np.empty(3), np.empty((3, 3)), np.empty((6, 6)), np.empty((6, 6)),
    )  # fmt: skip


@numba.njit(cache=True)
def update_column(
    c, v, length, locations, weights, elastic_flexibility, fibres, element, materials, current,
    limit, tolerance, scratch,
):  # fmt: skip
    """Bring column ``c`` to the basic deformations ``v [6]``.

    The trial element state (``element``, see :class:`.columns.ColumnState`) is advanced in place
    from its last trial value; the fibres are evaluated from their committed states
    (``materials`` buffers ``current``). At most ``limit`` element iterations: returns
    the number taken if the element's compatibility converged (the energy of its last
    correction below ``tolerance``, J), minus it if not; the state
    reached is kept either way (with ``limit = 1`` the element iterates along with the
    structure's Newton iterations, as in Neuenhofer and Filippou's non-iterative form).
    ``scratch`` is :func:`column_scratch`'s.
    """
    vt, q, kv, e, s, fs = element
    q_trial, dv_residual, vr, b, target, residual, increment, tangent, flexibility, work = scratch
    for m in range(6):
        total = q[c, m]
        for n in range(6):
            total += kv[c, m, n] * (v[n] - vt[c, n])
        q_trial[m] = total
    b[0] = 1.0
    k = current[c]
    for iteration in range(1, limit + 1):
        for m in range(6):
            total = 0.0
            for n in range(6):
                flexibility[m, n] = elastic_flexibility[m, n]
                total += elastic_flexibility[m, n] * q_trial[n]
            vr[m] = total
        for i in range(locations.size):
            xi = locations[i]
            wl = weights[i] * length
            target[0] = q_trial[0]
            target[1] = (xi - 1.0) * q_trial[1] + xi * q_trial[2]
            target[2] = (xi - 1.0) * q_trial[3] + xi * q_trial[4]
            for a in range(3):
                residual[a] = target[a] - s[c, i, a]
            for a in range(3):
                e[c, i, a] += (
                    fs[c, i, a, 0] * residual[0]
                    + fs[c, i, a, 1] * residual[1]
                    + fs[c, i, a, 2] * residual[2]
                )
            _section(fibres, materials, k, c, i, e[c, i], s[c, i], tangent)
            invert3(tangent, fs[c, i])
            # the deformations the section would need to carry the target forces
            for a in range(3):
                residual[a] = target[a] - s[c, i, a]
            for a in range(3):
                increment[a] = e[c, i, a] + (
                    fs[c, i, a, 0] * residual[0]
                    + fs[c, i, a, 1] * residual[1]
                    + fs[c, i, a, 2] * residual[2]
                )
            # b^T fs b and b^T (e + fs r); b maps (N, Mz_i, Mz_j, My_i, My_j) to the section
            b[1] = xi - 1.0
            b[2] = xi
            b[3] = xi - 1.0
            b[4] = xi
            for m in range(5):
                vr[m] += wl * b[m] * increment[ROW[m]]
                for n in range(5):
                    flexibility[m, n] += wl * b[m] * fs[c, i, ROW[m], ROW[n]] * b[n]
        if not invert(flexibility, kv[c], work):
            return -limit
        work_done = 0.0
        for m in range(6):
            dv_residual[m] = v[m] - vr[m]
        for m in range(6):
            dq = 0.0
            for n in range(6):
                dq += kv[c, m, n] * dv_residual[n]
            q_trial[m] += dq
            work_done += dv_residual[m] * dq
        if abs(work_done) < tolerance:
            q[c] = q_trial
            vt[c] = v
            return iteration
    q[c] = q_trial
    vt[c] = v
    return -limit


@numba.njit(cache=True)
def copy_element(source, target):
    """Copy the element state ``source`` (see :class:`.columns.ColumnState`) into ``target``."""
    target[0][...] = source[0]
    target[1][...] = source[1]
    target[2][...] = source[2]
    target[3][...] = source[3]
    target[4][...] = source[4]
    target[5][...] = source[5]


@numba.njit(cache=True)
def commit_columns(element, committed, current):
    """Accept every column's trial state: its fibre states, written to the spare buffer
    by the last evaluation, become the committed ones; the element state is copied."""
    copy_element(element, committed)
    for c in range(current.size):
        current[c] = 1 - current[c]


@numba.njit(cache=True)
def revert_columns(element, committed):
    """Return every column's element state to the last commit (the fibres are always
    evaluated from their committed states)."""
    copy_element(committed, element)
