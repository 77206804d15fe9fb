"""The bridge's linear representation, read from its elastic OpenSees model.

Only translational DOFs carry mass (lumped at the girder and column-top nodes); the
rotations are massless. The damping is Rayleigh, ``C = a0 M + a1 K0`` with ``K0`` the
initial stiffness, so a massless row of the equations of motion reads
``(1 + a1 d/dt) (K0 u)_o = 0`` and, from rest, ``(K0 u)_o = 0`` at every instant: static
condensation onto the mass-carrying DOFs is exact. This holds because the gravity
(P-Delta) stiffness ``K - K0`` lives on the column-top translations alone, which carry
mass; :func:`assemble` checks it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from cphysfno_core.plugin import LinearSystem, Rayleigh

from ..matrices import condense
from .design import BridgeDesign
from .model import TRANSVERSE, ElasticSection, apply_gravity, build, tangent_stiffness
from .numerics import Numerics


@dataclass(frozen=True)
class Matrices:
    """The elastic bridge condensed onto its mass-carrying DOFs (SI units).

    Attributes:
        mass: ``[n, n]`` lumped masses, kg.
        initial_stiffness: ``[n, n]`` K0 without gravity, N/m.
        stiffness: ``[n, n]`` K under gravity (with its P-Delta part), N/m.
        influence: ``[n]`` ones on the transverse DOFs.
        output_map: ``[10, n]`` picks each column top's transverse DOF.
        dofs: ``[n]`` ``(node, direction)`` of each DOF.
    """

    mass: np.ndarray
    initial_stiffness: np.ndarray
    stiffness: np.ndarray
    influence: np.ndarray
    output_map: np.ndarray
    dofs: tuple[tuple[int, int], ...]

    def frequencies(self) -> np.ndarray:
        """``[n]`` undamped circular frequencies of (K, M), rad/s, ascending."""
        squares = scipy.linalg.eigh(self.stiffness, self.mass, eigvals_only=True)
        return np.sqrt(squares)

    def rayleigh(self, ratio: float, second_period: float) -> Rayleigh:
        """Rayleigh factors on M and K0 giving ``ratio`` of critical at the first mode and
        at ``second_period`` (s)."""
        return Rayleigh.matching(self.frequencies()[0], 2.0 * math.pi / second_period, ratio)

    def linear_system(self, damping: Rayleigh) -> LinearSystem:
        """M, ``a0 M + a1 K0``, K, influence and output map."""
        c = damping.matrix(self.mass, self.initial_stiffness)
        return LinearSystem(self.mass, c, self.stiffness, self.influence, self.output_map)


def assemble(
    ops: Any, design: BridgeDesign, numerics: Numerics, elastic: ElasticSection
) -> Matrices:
    """Read K0 and K of the elastic bridge from OpenSees and condense them.

    Raises:
        RuntimeError: the gravity stiffness reaches a massless DOF, so condensation would
            not be exact.
    """
    where = build(ops, design, numerics, "elastic", elastic, gravity=False)
    initial = tangent_stiffness(ops)
    ops.wipeAnalysis()
    apply_gravity(ops, where)
    loaded = tangent_stiffness(ops)
    equations, dofs, masses = [], [], []
    for node in (*where.girder_nodes, *where.column_tops):
        numbers = ops.nodeDOFs(node)
        for direction in (1, 2, 3):
            if numbers[direction - 1] >= 0:
                equations.append(numbers[direction - 1])
                dofs.append((node, direction))
                masses.append(ops.nodeMass(node, direction))
    ops.wipe()
    keep = np.asarray(equations)
    others = np.setdiff1d(np.arange(initial.shape[0]), keep)
    geometric = loaded - initial
    if np.abs(geometric[others]).max() > 1e-9 * np.abs(initial).max():
        raise RuntimeError("the gravity stiffness reaches massless DOFs: cannot condense")
    output_map = np.zeros((len(where.column_tops), keep.size))
    for row, top in enumerate(where.column_tops):
        output_map[row, dofs.index((top, TRANSVERSE))] = 1.0
    influence = np.array([1.0 if direction == TRANSVERSE else 0.0 for _, direction in dofs])
    return Matrices(
        np.diag(masses),
        condense(initial, keep, others),
        condense(loaded, keep, others),
        influence,
        output_map,
        tuple(dofs),
    )
