"""Force-based reinforced-concrete columns, fixed at the base, in compiled code: their
constant data, their state, and how their tops' motion and forces map to the elements.

Each column is OpenSees' ``forceBeamColumn`` (Gauss-Lobatto sections, the iterative state
determination of :mod:`.state_determination`) on a ``PDelta`` transformation, with a
fibre section of three groups (confined core and cover in ``Concrete04``, bars in
``Steel02``) and elastic shear (``Vy``, ``Vz``) and torsion. Its base is fixed, so only
the six displacements of its top enter the structure.

Basic forces ``q = (N, Mz_i, Mz_j, My_i, My_j, T)`` and deformations ``v`` follow OpenSees'
3-d convention; a section at ``xi = x / L`` carries ``(N, Mz, My) = (q0, (xi - 1) q1 + xi
q2, (xi - 1) q3 + xi q4)``. All columns of a :class:`Columns` share the section and the
integration rule and differ in length and orientation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np

from .section import FibreGroup


@dataclass(frozen=True)
class Columns:
    """The constant data of a set of force-based columns.

    Attributes:
        core, cover, bars: the section's fibre groups.
        lengths: ``[c]`` column lengths, m.
        rotations: ``[c, 3, 3]`` rows: the local x (base to top), y and z axes in global
            coordinates.
        locations: ``[s]`` section locations ``xi``.
        weights: ``[s]`` integration weights (summing to 1).
        shear_stiffness: GA of each of ``Vy`` and ``Vz``, N.
        torsional_stiffness: GJ, N m^2.
        elastic_flexibility: ``[c, 6, 6]`` basic flexibility of shear and torsion.
        chords: ``[c, 6, 6]`` :func:`chord_map` of each column.
        drifts: ``[c, 3, 3]`` :func:`drift_map` of each column.
    """

    core: FibreGroup
    cover: FibreGroup
    bars: FibreGroup
    lengths: np.ndarray
    rotations: np.ndarray
    locations: np.ndarray
    weights: np.ndarray
    shear_stiffness: float
    torsional_stiffness: float
    elastic_flexibility: np.ndarray = field(init=False)
    chords: np.ndarray = field(init=False)
    drifts: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        flexibility = np.zeros((self.lengths.size, 6, 6))
        for c, length in enumerate(self.lengths):
            shear = 1.0 / (length * self.shear_stiffness)
            flexibility[c, 1:3, 1:3] = shear
            flexibility[c, 3:5, 3:5] = shear
            flexibility[c, 5, 5] = length / self.torsional_stiffness
        object.__setattr__(self, "elastic_flexibility", flexibility)
        pairs = zip(self.lengths, self.rotations, strict=True)
        chords = np.array([chord_map(length, rotation) for length, rotation in pairs])
        pairs = zip(self.lengths, self.rotations, strict=True)
        drifts = np.array([drift_map(length, rotation) for length, rotation in pairs])
        object.__setattr__(self, "chords", chords)
        object.__setattr__(self, "drifts", drifts)

    @property
    def count(self) -> int:
        return int(self.lengths.size)

    def initial_section_tangent(self, concrete_modulus: float, steel_modulus: float):
        """``[3, 3]`` section stiffness at zero strain (N, N m, N m^2)."""
        return (
            self.core.initial_tangent(concrete_modulus)
            + self.cover.initial_tangent(concrete_modulus)
            + self.bars.initial_tangent(steel_modulus)
        )

    def arrays(self) -> tuple:
        """``(lengths, chords, drifts, locations, weights, elastic_flexibility, fibres)``:
        the columns as the compiled analyses take them."""
        return (
            self.lengths,
            self.chords,
            self.drifts,
            self.locations,
            self.weights,
            self.elastic_flexibility,
            self.fibres,
        )

    @property
    def fibres(self) -> tuple[np.ndarray, ...]:
        """Parameters, ``y``, ``z`` and areas of the core, cover and bar groups, in order."""
        return tuple(
            array
            for group in (self.core, self.cover, self.bars)
            for array in (group.parameters, group.y, group.z, group.area)
        )

    def virgin(self, concrete_modulus: float, steel_modulus: float) -> ColumnState:
        """Every column at rest, unstrained."""
        c, s = self.count, self.locations.size
        section = np.linalg.inv(self.initial_section_tangent(concrete_modulus, steel_modulus))
        flexibility = np.broadcast_to(section, (c, s, 3, 3)).copy()
        stiffness = np.zeros((c, 6, 6))
        for k in range(c):
            total = self.elastic_flexibility[k].copy()
            basic = basic_flexibility(flexibility[k], self.locations, self.weights, self.lengths[k])
            total[:5, :5] += basic
            stiffness[k] = np.linalg.inv(total)
        element = (
            np.zeros((c, 6)),
            np.zeros((c, 6)),
            stiffness,
            np.zeros((c, s, 3)),
            np.zeros((c, s, 3)),
            flexibility,
        )
        materials = (self.core.states(2, c, s), self.cover.states(2, c, s),
                     self.bars.states(2, c, s))  # fmt: skip
        return ColumnState(
            element, tuple(a.copy() for a in element), materials, np.zeros(c, dtype=np.int64)
        )


def basic_flexibility(
    section_flexibility: np.ndarray, locations: np.ndarray, weights: np.ndarray, length: float
) -> np.ndarray:
    """``[5, 5]`` flexibility of ``(N, Mz_i, Mz_j, My_i, My_j)`` from the sections' ``[s, 3,
    3]`` flexibilities (no shear or torsion)."""
    out = np.zeros((5, 5))
    for fs, xi, w in zip(section_flexibility, locations, weights, strict=True):
        b = np.zeros((3, 5))
        b[0, 0] = 1.0
        b[1, 1:3] = xi - 1.0, xi
        b[2, 3:5] = xi - 1.0, xi
        out += w * length * b.T @ fs @ b
    return out


@dataclass
class ColumnState:
    """The state of every column.

    Attributes:
        element: the trial element state, arrays indexed by column first: basic
            deformations ``v [c, 6]``, basic forces ``q [c, 6]`` (N, N m), basic stiffness
            ``[c, 6, 6]``, section deformations and forces ``[c, s, 3]`` and section
            flexibilities ``[c, s, 3, 3]``.
        committed: the same at the last commit.
        materials: fibre states of the core, cover and bars, ``[2, c, s, n, n_state]``:
            two buffers per column, ``current[c]`` the committed one, the other written
            with the trial states at every evaluation.
        current: ``[c]`` which buffer holds the committed fibre states.
    """

    element: tuple[np.ndarray, ...]
    committed: tuple[np.ndarray, ...]
    materials: tuple[np.ndarray, np.ndarray, np.ndarray]
    current: np.ndarray

    @property
    def force(self) -> np.ndarray:
        """``[c, 6]`` trial basic forces."""
        return self.element[1]

    def arrays(self) -> tuple:
        """``(element, committed, materials, current)`` as the compiled analyses take them."""
        return (self.element, self.committed, self.materials, self.current)

    def copy(self) -> ColumnState:
        return ColumnState(
            tuple(a.copy() for a in self.element),
            tuple(a.copy() for a in self.committed),
            tuple(a.copy() for a in self.materials),
            self.current.copy(),
        )


def chord_map(length: float, rotation: np.ndarray) -> np.ndarray:
    """``[6, 6]`` map from the top's global displacements and rotations to the basic
    deformations of a column of ``length`` (m) with local axes ``rotation [3, 3]``, its
    base fixed (OpenSees' linear and P-Delta transformations)."""
    basic = np.zeros((6, 6))  # from the top's local (ux, uy, uz, rx, ry, rz)
    basic[0, 0] = 1.0
    basic[1, 1] = basic[2, 1] = -1.0 / length
    basic[2, 5] = 1.0
    basic[3, 2] = basic[4, 2] = 1.0 / length
    basic[4, 4] = 1.0
    basic[5, 3] = 1.0
    to_local = np.zeros((6, 6))
    to_local[:3, :3] = to_local[3:, 3:] = rotation
    return basic @ to_local


def drift_map(length: float, rotation: np.ndarray) -> np.ndarray:
    """``[3, 3]`` the top's lateral drift over the length (1/m) from its global
    translation: the P-Delta force is the axial force times it."""
    lateral = rotation[1:]
    return lateral.T @ lateral / length


@numba.njit(cache=True)
def basic_deformation(chord, top, v):
    """``v [6] = chord [6, 6] @ top [6]``: basic deformations from the top's motion."""
    for m in range(6):
        total = 0.0
        for k in range(6):
            total += chord[m, k] * top[k]
        v[m] = total


@numba.njit(cache=True)
def top_response(chord, drift, top, q, kv, force, stiffness, work):
    """Global force ``[6]`` and tangent ``[6, 6]`` that a column with basic forces ``q``
    and basic stiffness ``kv`` exerts on its top, displaced by ``top [6]`` (global):
    ``chord^T q`` and ``chord^T kv chord``, with OpenSees' P-Delta terms (the axial force
    times ``drift [3, 3]`` of :func:`drift_map`; no derivative of the axial force).
    ``work [6, 6]`` is scratch."""
    axial = q[0]
    for k in range(6):
        total = 0.0
        for m in range(6):
            total += chord[m, k] * q[m]
        force[k] = total
    for k in range(3):
        for j in range(3):
            force[k] += axial * drift[k, j] * top[j]
    for m in range(6):
        for k in range(6):
            total = 0.0
            for n in range(6):
                total += kv[m, n] * chord[n, k]
            work[m, k] = total
    for k in range(6):
        for j in range(6):
            total = 0.0
            for m in range(6):
                total += chord[m, k] * work[m, j]
            stiffness[k, j] = total
    for k in range(3):
        for j in range(3):
            stiffness[k, j] += axial * drift[k, j]
