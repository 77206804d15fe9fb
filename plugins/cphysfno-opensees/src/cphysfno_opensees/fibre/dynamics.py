"""Static and Newmark analyses of a linear structure carried by force-based columns.

The structure's equations ``M a + C v + K u + f(u_b) = p`` have a constant linear part
(``K``, ``C = a0 M + a1 K0``, lumped ``M``) and the columns' resisting forces ``f``, which
act on the ``b`` DOFs of the column tops only (their bases are fixed). A Newton iteration
of the whole system is then solved exactly on the column tops alone: the other DOFs are
eliminated once per analysis through the constant effective matrix ``A = K + c1 C + c2 M``
(Schur complement ``S = A_bb - A_bi A_ii^-1 A_ib``), so each iteration solves ``(S +
K_col) d_b = r_b`` and recovers ``d_i = -A_ii^-1 A_ib d_b``. The iterates are those of
OpenSees' ``Newton`` on the full system, and convergence is tested as OpenSees'
``NormDispIncr``: the 2-norm of the whole increment, ``|d_b|^2 + |d_i|^2``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from .columns import basic_deformation, top_response
from .state_determination import (
    column_scratch,
    commit_columns,
    copy_element,
    revert_columns,
    update_column,
)


@dataclass(frozen=True)
class Partition:
    """A constant effective matrix ``A`` split on the column-top DOFs.

    Attributes:
        interior: ``[n_i]`` equation numbers of the other DOFs.
        boundary: ``[c, 6]`` equation numbers of each column top's six DOFs.
        solve_interior: ``[n_i, n_i]`` ``A_ii^-1``.
        coupling: ``[n_i, n_b]`` ``A_ii^-1 A_ib``.
        boundary_rows: ``[n_b, n_i]`` ``A_bi``.
        schur: ``[n_b, n_b]`` ``A_bb - A_bi A_ii^-1 A_ib``.
    """

    interior: np.ndarray
    boundary: np.ndarray
    solve_interior: np.ndarray
    coupling: np.ndarray
    boundary_rows: np.ndarray
    schur: np.ndarray

    @classmethod
    def of(cls, matrix: np.ndarray, boundary: np.ndarray) -> Partition:
        """Split ``matrix [n, n]`` on the ``boundary [c, 6]`` equations."""
        flat = boundary.reshape(-1)
        interior = np.setdiff1d(np.arange(matrix.shape[0]), flat)
        inverse = np.linalg.inv(matrix[np.ix_(interior, interior)])
        coupling = inverse @ matrix[np.ix_(interior, flat)]
        rows = np.ascontiguousarray(matrix[np.ix_(flat, interior)])
        schur = matrix[np.ix_(flat, flat)] - rows @ coupling
        return cls(interior, boundary.astype(np.int64), inverse, coupling, rows, schur)

    def arrays(self) -> tuple[np.ndarray, ...]:
        return (
            self.interior,
            self.boundary,
            self.solve_interior,
            self.coupling,
            self.boundary_rows,
            self.schur,
        )


@numba.njit(cache=True)
def _update_all(columns, state, u_top, v_basic, limit, tolerance, counts):
    """Bring every column to its top's displacements ``u_top [c, 6]``; returns 1 if all
    of them converged (see :func:`update_column`) and 0 if some stopped at ``limit``
    element iterations."""
    lengths, chords, drifts, locations, weights, flexibility, fibres = columns
    element, committed, materials, current = state
    outcome = 1
    scratch = column_scratch()
    for c in range(lengths.size):
        basic_deformation(chords[c], u_top[c], v_basic)
        iterations = update_column(
            c, v_basic, lengths[c], locations, weights, flexibility[c], fibres, element,
            materials, current, limit, tolerance, scratch,
        )  # fmt: skip
        counts[1] += abs(iterations)
        if iterations < 0:
            outcome = 0
    return outcome


@numba.njit(cache=True, fastmath={"reassoc", "contract"})
def cholesky_solve(a, b, x):
    """Solve ``a x = b`` for a symmetric positive definite ``a [n, n]``, its lower
    triangle overwritten with the Cholesky factor. False if ``a`` is not positive
    definite: then ``x`` is undefined and ``a`` is symmetrised from its upper triangle.
    Its sums may be reordered (twice as fast; NaN and infinities keep their meaning)."""
    n = b.size
    diagonal = np.diag(a).copy()
    for j in range(n):
        d = a[j, j]
        for k in range(j):
            d -= a[j, k] * a[j, k]
        if not d > 0.0:
            for i in range(n):
                a[i, i] = diagonal[i]
                for k in range(i):
                    a[i, k] = a[k, i]
            return False
        d = np.sqrt(d)
        a[j, j] = d
        for i in range(j + 1, n):
            t = a[i, j]
            for k in range(j):
                t -= a[i, k] * a[j, k]
            a[i, j] = t / d
    for i in range(n):
        t = b[i]
        for j in range(i):
            t -= a[i, j] * x[j]
        x[i] = t / a[i, i]
    for i in range(n - 1, -1, -1):
        t = x[i]
        for j in range(i + 1, n):
            t -= a[j, i] * x[j]
        x[i] = t / a[i, i]
    return True


@numba.njit(cache=True)
def solve_increment(rhs, u_start, partition, columns, state, solver):
    """Newton iterations for ``A d + f(u_start + d) = rhs`` (``A`` the partition's
    matrix); returns ``(converged, d)``. The columns' trial states follow the iterates.

    ``solver = (tolerance, max_iterations, (element_limit, element_tolerance, skip),
    counts)``: the tolerance on the correction's 2-norm (the correction is applied and
    the columns evaluated there, as OpenSees' ``NormDispIncr`` does); the iterations
    allowed; the element iterations per column and Newton iteration (1: the elements
    converge along with the structure, which then also waits for them), the elements'
    energy tolerance (J), and the fraction of the tolerance below which a correction is
    not applied once the columns have converged (0: OpenSees' iterates; above 0, one
    column evaluation fewer and the answer moved by less than ``skip * tolerance``); and
    ``counts [2]`` to which the Newton and the element iterations taken are added.
    """
    tolerance, max_iterations, elements, counts = solver
    element_limit, element_tolerance, skip = elements
    interior, boundary, solve_interior, coupling, boundary_rows, schur = partition
    lengths, chords, drifts = columns[0], columns[1], columns[2]
    element = state[0]
    q, kv = element[1], element[2]
    n_columns = lengths.size
    n_b = 6 * n_columns
    flat = boundary.reshape(-1)
    z_i = solve_interior @ rhs[interior]
    g = rhs[flat] - boundary_rows @ z_i
    d_b = np.zeros(n_b)
    u_top = np.empty((n_columns, 6))
    force = np.empty(6)
    stiffness = np.empty((6, 6))
    work = np.empty((6, 6))
    v_basic = np.empty(6)
    converged = False
    elements_converged = True
    for _ in range(max_iterations):
        counts[0] += 1
        for c in range(n_columns):
            for k in range(6):
                u_top[c, k] = u_start[boundary[c, k]] + d_b[6 * c + k]
        residual = g - schur @ d_b
        tangent = schur.copy()
        for c in range(n_columns):
            top_response(chords[c], drifts[c], u_top[c], q[c], kv[c], force, stiffness, work)
            for k in range(6):
                residual[6 * c + k] -= force[k]
                for m in range(6):
                    tangent[6 * c + k, 6 * c + m] += stiffness[k, m]
        step = np.empty(n_b)
        if not cholesky_solve(tangent, residual, step):
            step = np.linalg.solve(tangent, residual)
        interior_step = coupling @ step
        norm = np.sqrt(step @ step + interior_step @ interior_step)
        small = norm <= tolerance
        if norm <= skip * tolerance and elements_converged:
            converged = True
            break
        d_b += step
        for c in range(n_columns):
            for k in range(6):
                u_top[c, k] = u_start[boundary[c, k]] + d_b[6 * c + k]
        outcome = _update_all(
            columns, state, u_top, v_basic, element_limit, element_tolerance, counts
        )
        if outcome == 0 and element_limit > 1:
            break
        elements_converged = outcome == 1
        if small and elements_converged:
            converged = True
            break
    d = np.empty(rhs.size)
    d[flat] = d_b
    d[interior] = z_i - coupling @ d_b
    return converged, d


@numba.njit(cache=True)
def static_steps(load, steps, stiffness, u, partition, columns, state, solver):
    """Apply ``load [n]`` in ``steps`` equal increments of load control from ``u [n]``
    (updated in place), committing the columns after each; ``partition`` splits the
    linear ``stiffness [n, n]``. False if a step did not converge."""
    element, committed, materials, current = state
    for j in range(1, steps + 1):
        rhs = (j / steps) * load - stiffness @ u
        ok, d = solve_increment(rhs, u, partition, columns, state, solver)
        if not ok:
            revert_columns(element, committed)
            return False
        u += d
        commit_columns(element, committed, current)
    return True


@numba.njit(cache=True)
def _newmark_step(dt, ground, linear, motion, partition, columns, state, solver):
    """One Newmark step of length ``dt`` to ground acceleration ``ground``; on success
    ``motion = (u, v, a)`` and the columns are advanced and committed, else nothing
    changes and False is returned."""
    mass, influence, load, stiffness, damping, gamma, beta = linear
    u, v, a = motion
    element, committed, materials, current = state
    c1 = gamma / (beta * dt)
    c2 = 1.0 / (beta * dt * dt)
    v_star = (1.0 - gamma / beta) * v + dt * (1.0 - gamma / (2.0 * beta)) * a
    a_star = -v / (beta * dt) + (1.0 - 1.0 / (2.0 * beta)) * a
    rhs = load - mass * (influence * ground + a_star) - stiffness @ u - damping @ v_star
    ok, d = solve_increment(rhs, u, partition, columns, state, solver)
    if not ok:
        revert_columns(element, committed)
        return False
    u += d
    v[:] = c1 * d + v_star
    a[:] = c2 * d + a_star
    commit_columns(element, committed, current)
    return True


SPLITS = (2, 4, 8)
"""Substeps a step that does not converge is split into, in turn."""


@numba.njit(cache=True)
def newmark(ground, dt, outputs, linear, motion, partitions, columns, state, solver, recovery):
    """Integrate from the state ``motion = (u, v, a)`` through ``ground [T]`` (ground
    acceleration at the end of each step of ``dt``, m/s^2).

    ``partitions[k]`` splits the effective matrix of the step ``dt / SPLITS[k - 1]``
    (``k = 0``: the step itself). A step that does not converge with ``solver`` (see
    :func:`solve_increment`) is tried again with ``recovery`` (typically the same with
    iterative elements), then with ``recovery`` split into 2, 4 and 8 steps (the record
    linear in between). Returns ``(u [T + 1, len(outputs)], failed)``: the output DOFs
    after every step (row 0: the start) and the index of the step that failed in every
    way, or -1.
    """
    u = motion[0]
    element, committed, materials, current = state
    out = np.empty((ground.size + 1, outputs.size))
    out[0] = u[outputs]
    previous = 0.0
    for j in range(ground.size):
        if not _newmark_step(
            dt, ground[j], linear, motion, partitions[0], columns, state, solver
        ) and not _newmark_step(
            dt, ground[j], linear, motion, partitions[0], columns, state, recovery
        ):
            saved_motion = (motion[0].copy(), motion[1].copy(), motion[2].copy())
            saved_committed = (
                committed[0].copy(), committed[1].copy(), committed[2].copy(),
                committed[3].copy(), committed[4].copy(), committed[5].copy(),
            )  # fmt: skip
            saved_materials = (materials[0].copy(), materials[1].copy(), materials[2].copy())
            saved_current = current.copy()
            recovered = False
            for k in range(len(SPLITS)):
                split = SPLITS[k]
                recovered = True
                for m in range(1, split + 1):
                    level = previous + (ground[j] - previous) * m / split
                    if not _newmark_step(
                        dt / split, level, linear, motion, partitions[k + 1], columns, state,
                        recovery,
                    ):  # fmt: skip
                        recovered = False
                        break
                if recovered:
                    break
                motion[0][:] = saved_motion[0]
                motion[1][:] = saved_motion[1]
                motion[2][:] = saved_motion[2]
                copy_element(saved_committed, committed)
                revert_columns(element, committed)
                materials[0][...] = saved_materials[0]
                materials[1][...] = saved_materials[1]
                materials[2][...] = saved_materials[2]
                current[:] = saved_current
            if not recovered:
                return out[: j + 1], j
        previous = ground[j]
        out[j + 1] = u[outputs]
    return out, -1
