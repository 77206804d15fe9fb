"""Fibre sections in three dimensions: section forces and tangent from section deformations.

A section's deformations are ``e = (eps0, kappa_z, kappa_y)`` (axial strain at the origin,
curvatures about the local z and y axes, 1/m); a fibre at ``(y, z)`` strains by
``eps0 - y kappa_z + z kappa_y`` and the section forces are ``(N, Mz, My) = sum (1, -y, z)
sigma A`` (N, N m), as in OpenSees' ``FiberSection3d``. The fibres of a section come in
groups of one uniaxial material each; every group's material is a module with the
``trial(p, committed, out, strain) -> (stress, tangent)`` of :mod:`.concrete04` and
:mod:`.steel02`, which computes a trial state from the committed one only, so that any
number of trials may precede a commit, and a parameter class of the
:class:`~.material.UniaxialMaterial` protocol.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from .material import UniaxialMaterial


@dataclass(frozen=True)
class FibreGroup:
    """Fibres of one material in a section.

    Attributes:
        y, z: ``[n]`` local coordinates of the fibres, m.
        area: ``[n]`` fibre areas, m^2.
        parameters: the material's packed parameter vector
            (:meth:`~.material.UniaxialMaterial.packed`).
        initial_state: ``[n_state]`` the material's virgin state.
    """

    y: np.ndarray
    z: np.ndarray
    area: np.ndarray
    parameters: np.ndarray
    initial_state: np.ndarray

    @classmethod
    def of(cls, fibres: np.ndarray, material: UniaxialMaterial) -> FibreGroup:
        """The group of ``fibres [n, 3]`` (``y``, ``z`` in m, area in m^2) of ``material``."""
        y, z, area = (np.ascontiguousarray(fibres[:, k]) for k in range(3))
        return cls(y, z, area, material.packed(), material.initial_state())

    def states(self, *leading: int) -> np.ndarray:
        """``[*leading, n, n_state]`` virgin states of this group in ``leading`` sections."""
        shape = (*leading, self.y.size, self.initial_state.size)
        return np.broadcast_to(self.initial_state, shape).copy()

    def initial_tangent(self, modulus: float) -> np.ndarray:
        """``[3, 3]`` section stiffness of these fibres at the initial ``modulus`` (Pa)."""
        tangent = np.zeros((3, 3))
        _add_fibres(tangent, self.y, self.z, self.area * modulus)
        return tangent


def _add_fibres(tangent: np.ndarray, y: np.ndarray, z: np.ndarray, ea: np.ndarray) -> None:
    arms = np.stack([np.ones_like(y), -y, z])
    tangent += (arms * ea) @ arms.T


@numba.njit(cache=True, inline="always")
def add_group(trial, p, y, z, area, committed, out, e, force, tangent):
    """Add one group's trial forces and tangent to ``force [3]`` and ``tangent [3, 3]``
    (upper triangle only; see :func:`symmetrise`).

    Args:
        trial: the group's material ``trial`` function.
        p: its parameters.
        y, z, area: ``[n]`` fibres (m, m, m^2).
        committed: ``[n, n_state]`` committed material states (read only).
        out: ``[n, n_state]`` the fibres' trial states, written.
        e: ``[3]`` section deformations.
    """
    # sums in scalars: the stores of the trial states could alias the arrays
    e0, e1, e2 = e[0], e[1], e[2]
    f0, f1, f2 = force[0], force[1], force[2]
    k00, k01, k02 = tangent[0, 0], tangent[0, 1], tangent[0, 2]
    k11, k12, k22 = tangent[1, 1], tangent[1, 2], tangent[2, 2]
    for f in range(y.size):
        yf, zf = y[f], z[f]
        stress, modulus = trial(p, committed[f], out[f], e0 - yf * e1 + zf * e2)
        fa = stress * area[f]
        ka = modulus * area[f]
        ky = -yf * ka
        kz = zf * ka
        f0 += fa
        f1 -= yf * fa
        f2 += zf * fa
        k00 += ka
        k01 += ky
        k02 += kz
        k11 -= yf * ky
        k12 -= yf * kz
        k22 += zf * kz
    force[0], force[1], force[2] = f0, f1, f2
    tangent[0, 0], tangent[0, 1], tangent[0, 2] = k00, k01, k02
    tangent[1, 1], tangent[1, 2], tangent[2, 2] = k11, k12, k22


@numba.njit(cache=True, inline="always")
def symmetrise(tangent):
    """Copy the upper triangle of ``tangent [3, 3]`` into its lower one."""
    tangent[1, 0] = tangent[0, 1]
    tangent[2, 0] = tangent[0, 2]
    tangent[2, 1] = tangent[1, 2]


@numba.njit(cache=True, inline="always")
def invert3(a, out):
    """``out = inverse(a)`` for a ``[3, 3]`` matrix (by cofactors)."""
    c00 = a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]
    c01 = a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]
    c02 = a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]
    inverse_det = 1.0 / (a[0, 0] * c00 + a[0, 1] * c01 + a[0, 2] * c02)
    out[0, 0] = c00 * inverse_det
    out[1, 0] = c01 * inverse_det
    out[2, 0] = c02 * inverse_det
    out[0, 1] = (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) * inverse_det
    out[1, 1] = (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) * inverse_det
    out[2, 1] = (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) * inverse_det
    out[0, 2] = (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1]) * inverse_det
    out[1, 2] = (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2]) * inverse_det
    out[2, 2] = (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]) * inverse_det


@numba.njit(cache=True)
def invert(a, out, work):
    """``out = inverse(a)`` for a small ``[n, n]`` matrix by Gauss-Jordan elimination with
    partial pivoting; ``work [n, n]`` is scratch. Returns False if ``a`` is singular."""
    n = a.shape[0]
    work[:, :] = a
    out[:, :] = 0.0
    for i in range(n):
        out[i, i] = 1.0
    for col in range(n):
        pivot = col
        for row in range(col + 1, n):
            if abs(work[row, col]) > abs(work[pivot, col]):
                pivot = row
        if work[pivot, col] == 0.0:
            return False
        if pivot != col:
            for k in range(n):
                work[col, k], work[pivot, k] = work[pivot, k], work[col, k]
                out[col, k], out[pivot, k] = out[pivot, k], out[col, k]
        scale = 1.0 / work[col, col]
        for k in range(n):
            work[col, k] *= scale
            out[col, k] *= scale
        for row in range(n):
            if row != col:
                factor = work[row, col]
                if factor != 0.0:
                    for k in range(n):
                        work[row, k] -= factor * work[col, k]
                        out[row, k] -= factor * out[col, k]
    return True
