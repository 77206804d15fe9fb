"""The linear equations of motion of an OpenSees model, read from OpenSees itself.

OpenSees assembles the mass, damping and stiffness of a model's equations with its
``GimmeMCK`` integrator: ``printA`` then returns ``m M + c C + k K`` for the integrator's
coefficients ``(m, c, k)``, each matrix as the elements and nodes of the model actually
contribute it at the domain's current state (the tangent stiffness, with any geometric
stiffness of the loads the model carries; the Rayleigh damping of each element, which some
elements, ``zeroLength`` among them, leave out unless asked). :func:`assemble` reads them.

With the ``Penalty`` constraint handler every node DOF keeps its own equation (fixed and
constrained DOFs too), and the handler adds its penalty terms ``P`` to every matrix it
assembles; read with a unit penalty, ``P`` tells which combinations of DOFs the fixities and
multi-point constraints allow (its null space), whatever kind of constraint they are
(``equalDOF``, ``rigidLink``, ``rigidDiaphragm``, chains of them). :func:`reduce` eliminates
the constrained DOFs exactly through that null space and then condenses the DOFs that
carry no mass statically:

- constraints: ``u = B q`` with ``q`` a set of independent DOFs of the model (those that
  carry mass preferred), and ``M_q = B^T M B``, ``C_q = B^T C B``, ``K_q = B^T K B``;
- massless DOFs ``o`` follow the others ``m`` statically, ``q_o = -K_oo^-1 K_om q_m``, and
  ``T = [I; -K_oo^-1 K_om]`` condenses ``K`` (exactly, for the periods) and ``C``
  (``T^T C T``: exact where the damping of the massless DOFs is proportional to their
  stiffness, as with Rayleigh damping on a stiffness without geometric or ``zeroLength``
  terms there; otherwise the usual Guyan approximation).
"""

from __future__ import annotations

import contextlib
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.csgraph

UNIT_PENALTY = ("Penalty", 1.0, 1.0)
"""The handler :func:`assemble` reads the constraints with: a unit penalty, so that its
terms stay of order one beside the matrices, and subtracting them again costs no more
than round-off."""

NULL_TOLERANCE = 1e-10
"""Eigenvalues of a block of penalty terms below this share of its largest are its null
space (the penalty terms are sums of squares of constraint coefficients, so the others
are of order one)."""

MASSLESS_TOLERANCE = 1e-12
"""A DOF whose mass row is below this share of the largest mass carries no mass."""


class ReductionError(ValueError):
    """The equations cannot be reduced: a DOF without mass has no stiffness either (a
    mechanism), or the mass matrix is not positive definite on the DOFs that carry mass."""


@dataclass(frozen=True)
class Equations:
    """Mass, damping and stiffness of an OpenSees model's equations, as assembled.

    Attributes:
        mass, damping, stiffness: ``[n, n]`` over the equations, in the model's units.
        constraint: ``[n, n]`` the constraint handler's own terms (zero for handlers that
            eliminate the constrained DOFs).
        equations: ``(node, dof)`` -> equation number, for the DOFs that have one (dof
            counted from 1).
    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    constraint: np.ndarray
    equations: dict[tuple[int, int], int]

    @property
    def size(self) -> int:
        return self.mass.shape[0]


def printed_matrix(
    ops: Any, constraints: Sequence[Any], m: float, c: float, k: float
) -> tuple[np.ndarray, dict[tuple[int, int], int]]:
    """The matrix ``m M + c C + k K`` (``[n, n]``) OpenSees assembles for the model as it
    stands, and ``(node, dof)`` -> equation of every node DOF that has one under the
    handler ``constraints`` (dof counted from 1; equations in node-tag order, ``Plain``
    numberer).

    The domain is not changed: ``GimmeMCK`` does not update it, and the solve that follows
    the assembly (of a matrix that may be singular) is not used. OpenSees' messages about
    that solve are dropped. The analysis is wiped afterwards.
    """
    ops.wipeAnalysis()
    ops.constraints(*constraints)
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", 1.0, 1)
    ops.algorithm("Linear")
    ops.integrator("GimmeMCK", float(m), float(c), float(k))
    ops.analysis("Transient")
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        ops.analyze(1, 0.0)
        values = np.asarray(ops.printA("-ret"), dtype=np.float64)
        numbers = {
            (node, dof + 1): equation
            for node in ops.getNodeTags()
            for dof, equation in enumerate(ops.nodeDOFs(node))
            if equation >= 0
        }
    ops.wipeAnalysis()
    n = int(round(math.sqrt(values.size)))
    return values.reshape(n, n), numbers


def assemble(ops: Any, *, damping: bool = True) -> Equations:
    """Read M, C (unless ``damping`` is False: zeros) and K of the model at its current
    state, every node DOF an equation (:data:`UNIT_PENALTY`); the analysis is wiped
    afterwards.

    The Rayleigh factors must be set (``ops.rayleigh``) before C is read.
    """
    constraint, numbers = printed_matrix(ops, UNIT_PENALTY, 0.0, 0.0, 0.0)
    mass = printed_matrix(ops, UNIT_PENALTY, 1.0, 0.0, 0.0)[0] - constraint
    stiffness = printed_matrix(ops, UNIT_PENALTY, 0.0, 0.0, 1.0)[0] - constraint
    if damping:
        damping_matrix = printed_matrix(ops, UNIT_PENALTY, 0.0, 1.0, 0.0)[0] - constraint
    else:
        damping_matrix = np.zeros_like(mass)
    return Equations(mass, damping_matrix, stiffness, constraint, numbers)


@dataclass(frozen=True)
class Reduced:
    """Equations reduced onto independent DOFs that carry mass.

    Attributes:
        mass, damping, stiffness: ``[r, r]``, symmetric.
        dofs: ``[r]`` ``(node, dof)`` of each retained DOF (a DOF of the model; its
            displacement is the coordinate).
        shapes: ``[n, r]`` the displacement of every equation of :class:`Equations` per
            unit of each retained DOF (constraints and static condensation together).
    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    dofs: tuple[tuple[int, int], ...]
    shapes: np.ndarray

    def frequencies(self) -> np.ndarray:
        """``[r]`` undamped circular frequencies (rad/s), ascending."""
        squares = scipy.linalg.eigh(self.stiffness, self.mass, eigvals_only=True)
        return np.sqrt(np.clip(squares, 0.0, None))


def reduce(equations: Equations, prefer: Sequence[tuple[int, int]] = ()) -> Reduced:
    """Eliminate the constrained DOFs of ``equations`` and condense those without mass.

    Args:
        equations: from :func:`assemble`.
        prefer: DOFs to keep as coordinates where a constraint leaves a choice (after
            those that carry mass), e.g. the retained DOFs of multi-point constraints.

    Raises:
        ReductionError: DOFs without mass whose stiffness is singular (a mechanism), or no
            DOF carries mass.
    """
    n = equations.size
    labels = sorted(equations.equations, key=equations.equations.__getitem__)
    if [equations.equations[label] for label in labels] != list(range(n)):
        raise ReductionError("the equations are not numbered 0 .. n-1 by node DOF")
    weight = np.ones(n)
    preferred = {equations.equations[d] for d in prefer if d in equations.equations}
    weight[list(preferred)] = 2.0
    weight[np.abs(equations.mass).sum(axis=1) > 0.0] = 4.0
    basis, independent = constraint_basis(equations.constraint, weight)
    mass = basis.T @ equations.mass @ basis
    stiffness = basis.T @ equations.stiffness @ basis
    damping = basis.T @ equations.damping @ basis
    # DOFs coupled to nothing (e.g. the rotations of nodes joined by trusses alone) play
    # no part in the motion.
    idle = (
        (np.abs(mass).sum(axis=1) == 0.0)
        & (np.abs(stiffness).sum(axis=1) == 0.0)
        & (np.abs(damping).sum(axis=1) == 0.0)
    )
    active = np.flatnonzero(~idle)
    scale = np.abs(mass).max(initial=0.0)
    if scale == 0.0:
        raise ReductionError("no DOF of the model carries mass")
    row_mass = np.abs(mass).sum(axis=1)
    carrying = active[row_mass[active] > MASSLESS_TOLERANCE * scale]
    massless = active[row_mass[active] <= MASSLESS_TOLERANCE * scale]
    condense = np.zeros((basis.shape[1], carrying.size))
    condense[carrying, np.arange(carrying.size)] = 1.0
    if massless.size:
        k_oo = stiffness[np.ix_(massless, massless)]
        k_om = stiffness[np.ix_(massless, carrying)]
        if _singular(k_oo):
            names = [labels[independent[i]] for i in massless[:5]]
            raise ReductionError(
                f"the DOFs without mass have a singular stiffness (a mechanism), among them "
                f"(node, dof) {names}"
            )
        follow = -np.linalg.solve(k_oo, k_om)
        condense[massless] = follow
    reduced_mass = _symmetric(condense.T @ mass @ condense)
    try:
        np.linalg.cholesky(reduced_mass)
    except np.linalg.LinAlgError:
        raise ReductionError("the mass matrix is not positive definite") from None
    return Reduced(
        mass=reduced_mass,
        damping=_symmetric(condense.T @ damping @ condense),
        stiffness=_symmetric(condense.T @ stiffness @ condense),
        dofs=tuple(labels[independent[i]] for i in carrying),
        shapes=basis @ condense,
    )


def constraint_basis(constraint: np.ndarray, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(B [n, q], independent [q])``: the displacements ``u = B q`` that the penalty terms
    ``constraint`` allow, in terms of ``q`` independent equations (``B[independent] = I``).

    Each connected block of ``constraint`` is treated alone: its null space is spanned by
    its eigenvectors of (relatively) zero eigenvalue, and its independent equations are
    chosen by a QR factorisation with column pivoting of that basis, each equation's column
    scaled by ``weight`` (larger: kept in preference).
    """
    n = constraint.shape[0]
    touched = np.flatnonzero(np.abs(constraint).sum(axis=1) > 0.0)
    columns: list[np.ndarray] = []
    independent: list[int] = []
    free = np.setdiff1d(np.arange(n), touched)
    for equation in free:
        column = np.zeros(n)
        column[equation] = 1.0
        columns.append(column)
        independent.append(int(equation))
    if touched.size:
        graph = scipy.sparse.csr_matrix(constraint[np.ix_(touched, touched)] != 0.0)
        count, label = scipy.sparse.csgraph.connected_components(graph, directed=False)
        for component in range(count):
            members = touched[label == component]
            block = constraint[np.ix_(members, members)]
            values, vectors = scipy.linalg.eigh(0.5 * (block + block.T))
            null = vectors[:, values <= NULL_TOLERANCE * np.abs(values).max()]
            if not null.shape[1]:
                continue
            _, _, pivots = scipy.linalg.qr(null.T * weight[members], pivoting=True)
            chosen = pivots[: null.shape[1]]
            shapes = null @ np.linalg.inv(null[chosen])
            shapes[np.abs(shapes) < 1e-14] = 0.0
            for j, local in enumerate(chosen):
                column = np.zeros(n)
                column[members] = shapes[:, j]
                column[members[local]] = 1.0
                columns.append(column)
                independent.append(int(members[local]))
    order = np.argsort(independent, kind="stable")
    basis = np.stack(columns, axis=1)[:, order] if columns else np.zeros((n, 0))
    return basis, np.asarray(independent, dtype=np.int64)[order]


def _singular(matrix: np.ndarray) -> bool:
    """Whether the stiffness ``matrix`` is singular to working precision: a diagonal term
    that is not positive, or a condition number of at least 1e14 once every DOF is scaled
    to a unit diagonal (so that a DOF held only by a very soft spring, such as the 1e-9
    kip in/rad springs of a leaning column's hinges, is soft, not a mechanism)."""
    if not matrix.size:
        return False
    diagonal = np.diag(matrix)
    if not np.all(diagonal > 0.0):
        return True
    scale = 1.0 / np.sqrt(diagonal)
    with np.errstate(all="ignore"):
        condition = np.linalg.cond(matrix * scale[:, None] * scale[None, :])
    return not bool(condition < 1e14)


def _symmetric(matrix: np.ndarray) -> np.ndarray:
    return 0.5 * (matrix + matrix.T)


def condense(matrix: np.ndarray, keep: np.ndarray, others: np.ndarray) -> np.ndarray:
    """Static condensation ``A_kk - A_ko A_oo^-1 A_ok`` of ``matrix`` onto the equations
    ``keep``, symmetrised."""
    kk = matrix[np.ix_(keep, keep)]
    ko = matrix[np.ix_(keep, others)]
    oo = matrix[np.ix_(others, others)]
    return _symmetric(kk - ko @ np.linalg.solve(oo, ko.T))


def eigenvalues(
    ops: Any, constraints: Sequence[Any], n: int, system: str = "FullGeneral"
) -> np.ndarray:
    """``[n]`` smallest eigenvalues omega^2 (rad^2/s^2) OpenSees finds for the model's
    current stiffness and its mass under the handler ``constraints``, by its dense
    generalised solver (massless DOFs allowed; OpenSees warns on every such solve that it
    is slow, and it takes milliseconds for models of a few hundred DOFs), the equations
    numbered in node-tag order and ``system`` the linear solver defined beside it. The
    analysis is wiped before and after. OpenSees' messages are dropped unless the solve
    fails, when they are raised in a RuntimeError."""
    ops.wipeAnalysis()
    ops.constraints(*constraints)
    ops.numberer("Plain")
    ops.system(system)
    messages = io.StringIO()
    try:
        with contextlib.redirect_stderr(messages), contextlib.redirect_stdout(messages):
            values = np.asarray(ops.eigen("-fullGenLapack", int(n)), dtype=np.float64)
    except Exception as error:
        raise RuntimeError(f"OpenSees' eigen analysis failed: {messages.getvalue()}") from error
    finally:
        ops.wipeAnalysis()
    return values
