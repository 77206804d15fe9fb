"""The fibre bridge analysed in compiled code instead of OpenSees, with the same answer.

Everything linear (girder, bent caps, abutment springs, masses, the initial stiffness of
the Rayleigh damping, gravity loads) is read from the OpenSees model itself; the ten
force-based fibre columns are evaluated by :mod:`cphysfno_opensees.fibre` (OpenSees'
element, section and materials, checked against them in the tests) and the
Newmark-Newton iterations run on the column tops alone
(:mod:`cphysfno_opensees.fibre.dynamics`). The result is OpenSees' ``forceBeamColumn``
bridge of :mod:`.model` to the Newton tolerance.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from cphysfno_core.plugin import Rayleigh

from ..fibre.columns import Columns, ColumnState
from ..fibre.dynamics import SPLITS, Partition, newmark, static_steps
from ..fibre.section import FibreGroup
from ..fibre.state_determination import (
    COMPATIBILITY_TOLERANCE,
    ELEMENT_ITERATIONS,
    ELEMENT_TOLERANCE,
)
from ..loader import import_opensees
from ..quadrature import lobatto
from ..transient import AnalysisFailed
from .analysis import analyse as opensees_analysis
from .column import column_materials, section_fibres, shear_and_torsion_stiffness
from .design import GRAVITY, BridgeDesign
from .model import TRANSVERSE, build, tangent_stiffness
from .numerics import Numerics

ITERATIVE = (ELEMENT_ITERATIONS, ELEMENT_TOLERANCE, 0.0)
"""OpenSees' iterations: every column converged at every Newton iteration, the last
correction applied (see :func:`cphysfno_opensees.fibre.dynamics.solve_increment`)."""
NON_ITERATIVE = (1, COMPATIBILITY_TOLERANCE, 0.01)
"""Columns that converge along with the structure, and no column evaluation after a
correction below a hundredth of the tolerance. On the bridge's records the answer is
9e-5 relative L2 from OpenSees' iterates (about what any change of path does to it, see
``COMPATIBILITY_TOLERANCE``), and the columns are evaluated 1.85 times a step instead of
2.5. Skipping larger corrections saves little more (1.7 times a step below a
tenth) and moves the first second of a strong record by up to 9e-4."""
LOGGER = logging.getLogger(__name__)
RECOVERY = "Newton, then with iterative elements, at dt and at dt/2, dt/4, dt/8"
"""What a step that fails has been tried with, in words."""
GRAVITY_STEPS = 10
"""Load steps of the gravity analysis (as in :func:`.model.apply_gravity`)."""
GRAVITY_TOLERANCE = 1e-12
"""Its Newton tolerance on the displacement increment, m."""


@dataclass(frozen=True)
class CompiledBridge:
    """The bridge's equations, ready for :func:`analyse_compiled` (SI units).

    Attributes:
        mass: ``[n]`` lumped mass of each equation, kg (zero on rotations).
        stiffness: ``[n, n]`` the linear elements' stiffness (no columns).
        initial_stiffness: ``[n, n]`` every element's initial stiffness (for the damping).
        gravity: ``[n]`` the weights of the lumped masses, N.
        influence: ``[n]`` ones on the transverse translations.
        tops: ``[c, 6]`` the equations of each column top.
        outputs: ``[c]`` the transverse equation of each column top.
        columns: the fibre columns.
        concrete_modulus, steel_modulus: initial moduli of the fibres, Pa.
    """

    mass: np.ndarray
    stiffness: np.ndarray
    initial_stiffness: np.ndarray
    gravity: np.ndarray
    influence: np.ndarray
    tops: np.ndarray
    outputs: np.ndarray
    columns: Columns
    concrete_modulus: float
    steel_modulus: float
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    def virgin(self) -> ColumnState:
        return self.columns.virgin(self.concrete_modulus, self.steel_modulus)

    def at_rest(self) -> tuple[np.ndarray, ColumnState]:
        """A fresh copy of :func:`at_rest_under_gravity` (computed once)."""
        if "at_rest" not in self._cache:
            self._cache["at_rest"] = at_rest_under_gravity(self)
        u, state = self._cache["at_rest"]
        return u.copy(), state.copy()

    def damping_matrix(self, damping: Rayleigh) -> np.ndarray:
        """``[n, n]`` Rayleigh damping ``a0 M + a1 K0``, N s/m."""
        return damping.matrix(np.diag(self.mass), self.initial_stiffness)

    def partitions(self, damping: Rayleigh, step: float) -> tuple:
        """The partitions of Newmark's effective matrix for the step ``step`` (s) and for
        it split by each of ``SPLITS`` (computed once per damping and step)."""
        key = ("partitions", damping, step)
        if key not in self._cache:
            matrix = self.damping_matrix(damping)
            self._cache[key] = tuple(
                Partition.of(effective_matrix(self, matrix, step / split), self.tops).arrays()
                for split in (1, *SPLITS)
            )
        return self._cache[key]


def fibre_columns(design: BridgeDesign, numerics: Numerics) -> Columns:
    """The ten columns of :func:`.model.build`: the same fibres, materials,
    integration and orientation."""
    materials = column_materials(design)
    core_fibres, cover_fibres, bars = section_fibres(design, numerics)
    locations, weights = lobatto(numerics.integration_points)
    heights = [h for h in design.pier_heights for _ in (0, 1)]
    # local x up the column; y = (1, 0, 0) x x and z = x x y, as OpenSees' vecxz = (1, 0, 0)
    axis_x = np.array([0.0, 0.0, 1.0])
    axis_y = np.cross([1.0, 0.0, 0.0], axis_x)
    rotation = np.stack([axis_x, axis_y, np.cross(axis_x, axis_y)])
    shear, torsion = shear_and_torsion_stiffness(design)
    return Columns(
        core=FibreGroup.of(core_fibres, materials.core),
        cover=FibreGroup.of(cover_fibres, materials.cover),
        bars=FibreGroup.of(bars, materials.bars),
        lengths=np.asarray(heights, dtype=np.float64),
        rotations=np.broadcast_to(rotation, (len(heights), 3, 3)).copy(),
        locations=locations,
        weights=weights,
        shear_stiffness=shear,
        torsional_stiffness=torsion,
    )


def compile_bridge(ops: Any, design: BridgeDesign, numerics: Numerics) -> CompiledBridge:
    """Read the linear part of the fibre bridge from OpenSees and set up its columns.

    The domain is wiped before and after.
    """
    where = build(ops, design, numerics, "fibre", gravity=False)
    initial = tangent_stiffness(ops)
    n = initial.shape[0]
    mass = np.zeros(n)
    gravity = np.zeros(n)
    influence = np.zeros(n)
    for node in (*where.girder_nodes, *where.column_tops):
        numbers = ops.nodeDOFs(node)
        for direction in (1, 2, 3):
            equation = numbers[direction - 1]
            if equation >= 0:
                mass[equation] = ops.nodeMass(node, direction)
                influence[equation] = 1.0 if direction == TRANSVERSE else 0.0
        if numbers[2] >= 0:
            gravity[numbers[2]] = -ops.nodeMass(node, 3) * GRAVITY
    tops = np.array([ops.nodeDOFs(top) for top in where.column_tops], dtype=np.int64)
    if (tops < 0).any():
        raise RuntimeError("a column top has a constrained DOF: the compiled bridge needs all six")
    for b in range(len(where.bents)):
        for s in (0, 1):
            ops.remove("element", 4000 + 10 * b + s)
    ops.wipeAnalysis()
    linear = tangent_stiffness(ops)
    ops.wipe()
    return CompiledBridge(
        mass=mass,
        stiffness=linear,
        initial_stiffness=initial,
        gravity=gravity,
        influence=influence,
        tops=tops,
        outputs=np.ascontiguousarray(tops[:, TRANSVERSE - 1]),
        columns=fibre_columns(design, numerics),
        concrete_modulus=design.concrete_modulus,
        steel_modulus=design.steel_modulus,
    )


def at_rest_under_gravity(bridge: CompiledBridge) -> tuple[np.ndarray, ColumnState]:
    """``(u [n], columns)``: the bridge brought to rest under its weight by load control."""
    state = bridge.virgin()
    u = np.zeros(bridge.mass.size)
    partition = Partition.of(bridge.stiffness, bridge.tops)
    ok = static_steps(
        bridge.gravity, GRAVITY_STEPS, bridge.stiffness, u, partition.arrays(),
        bridge.columns.arrays(), state.arrays(),
        (GRAVITY_TOLERANCE, 50, ITERATIVE, np.zeros(2, dtype=np.int64)),
    )  # fmt: skip
    if not ok:
        raise RuntimeError("the bridge does not carry its own weight: check the design")
    return u, state


def analyse_compiled(
    bridge: CompiledBridge,
    numerics: Numerics,
    damping: Rayleigh,
    acceleration: np.ndarray,
    dt: float,
) -> np.ndarray:
    """Transverse column-top displacements of the bridge under one ground motion: the
    result of :func:`.analysis.analyse` with fibre columns, computed here.

    Args:
        bridge: from :func:`compile_bridge`.
        numerics: substeps, tolerance and iterations of the analysis.
        damping: Rayleigh factors (``alphaM``, ``betaKinit``).
        acceleration: ``[T]`` ground acceleration, m/s^2 (linear between samples).
        dt: its time step, s.

    Returns:
        ``[T, 10]`` displacements relative to the ground (m) from the gravity state.

    Raises:
        AnalysisFailed: a step did not converge, even with iterative elements and split
            into 8.
    """
    u, state = bridge.at_rest()
    k = numerics.substeps
    fine = on_substeps(acceleration, k)
    step = dt / k
    damping_matrix = bridge.damping_matrix(damping)
    partitions = bridge.partitions(damping, step)
    linear = (
        bridge.mass,
        bridge.influence,
        bridge.gravity,
        bridge.stiffness,
        damping_matrix,
        0.5,
        0.25,
    )
    motion = (u.copy(), np.zeros_like(u), np.zeros_like(u))
    at_rest = u[bridge.outputs].copy()
    counts = np.zeros(2, dtype=np.int64)
    elements = ITERATIVE if numerics.iterative_elements else NON_ITERATIVE
    solver = (numerics.tolerance, numerics.max_iterations, elements, counts)
    recovery = (numerics.tolerance, numerics.max_iterations, ITERATIVE, counts)
    out, failed = newmark(
        fine[1:], step, bridge.outputs, linear, motion, partitions,
        bridge.columns.arrays(), state.arrays(), solver, recovery,
    )  # fmt: skip
    if failed >= 0:
        raise AnalysisFailed(failed * step, RECOVERY)
    return out[::k] - at_rest


def on_substeps(acceleration: np.ndarray, substeps: int) -> np.ndarray:
    """``[substeps * (T - 1) + 1]`` the record ``acceleration [T]`` (m/s^2) at every
    Newmark substep, linear between its samples."""
    values = np.asarray(acceleration, dtype=np.float64)
    times = np.arange(substeps * (values.size - 1) + 1) / substeps
    return np.interp(times, np.arange(values.size), values)


def effective_matrix(bridge: CompiledBridge, damping: np.ndarray, step: float) -> np.ndarray:
    """``K + 2/dt C + 4/dt^2 M``: the linear part of Newmark's (average acceleration)
    effective stiffness for the step ``dt`` (s)."""
    return bridge.stiffness + (2.0 / step) * damping + (4.0 / step**2) * np.diag(bridge.mass)


def analyse(
    design: BridgeDesign,
    numerics: Numerics,
    damping: Rayleigh,
    acceleration: np.ndarray,
    dt: float,
) -> np.ndarray:
    """:func:`analyse_compiled` for a worker process: reads the bridge from OpenSees on
    first use, and keeps BLAS to one thread (its threads would spin between the small
    solves of every step). A record the compiled engine cannot finish is handed to
    OpenSees (:func:`.analysis.analyse`), whose convergence ladder
    (``numerics.convergence``) sometimes gets through where Newton does not (a few records
    in a hundred on the 0.1 s grid of ``relaxed``); if OpenSees fails too, its failure is
    raised."""
    bridge = _compiled(design, numerics)
    try:
        with threadpool_limits(1):
            return analyse_compiled(bridge, numerics, damping, acceleration, dt)
    except AnalysisFailed as failure:
        LOGGER.info("compiled engine: %s; the record goes to OpenSees", failure)
    return opensees_analysis(design, numerics, damping, "fibre", None, acceleration, dt)


_CACHE: dict[tuple, CompiledBridge] = {}


def _compiled(design: BridgeDesign, numerics: Numerics) -> CompiledBridge:
    key = (design, numerics)
    if key not in _CACHE:
        ops = import_opensees()
        ops.logFile(os.devnull, "-noEcho")
        _CACHE[key] = compile_bridge(ops, design, numerics)
    return _CACHE[key]
