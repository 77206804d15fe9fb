"""What the framework learns of a user's model before analysing records: the constraint
handler that works for it, its damping, and its linear equations at the gravity
state (runs in a worker process, see :func:`probe`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.linalg

from ..loader import import_opensees
from ..matrices import Equations, ReductionError, assemble, eigenvalues, printed_matrix, reduce
from ..messages import captured
from .damping import DampingChoice, DampingSetup
from .model import ModelSpec, apply_gravity, build_model
from .source import ScriptError

PENALTY_FACTOR = 1e8
"""The penalty of the ``Penalty`` handler over the largest diagonal stiffness of the
model: its constraints then hold to about 1e-8 of the deformation."""

CONSISTENCY = 1e-5
"""Relative difference within which a handler's eigenvalues and gravity state must match
the exactly constrained model's for the handler to be taken as enforcing its constraints."""

CHECKED_MODES = 6
"""Eigenvalues compared when a handler is checked (fewer if the model has fewer)."""


@dataclass(frozen=True)
class Summary:
    """The model as the probe found it (the model's own units).

    Attributes:
        constraints: the ``ops.constraints`` arguments every analysis uses.
        checks: ``(handler, finding)`` for each handler tried, in words.
        ndm: spatial dimensions.
        mass, damping, stiffness: ``[r, r]`` the linear equations at the gravity state,
            constrained DOFs eliminated and massless ones condensed.
        dofs: ``[r]`` ``(node, dof)`` of the retained DOFs.
        output_map: ``[n_outputs, r]`` each output's displacement per unit of each DOF.
        influence: ``[r]`` the ground-motion influence vector of the excitation DOF.
        damping_setup: the damping commands every analysis sets after gravity.
        opensees_periods: the first periods (s) from OpenSees' own eigen analysis under
            the chosen handler, where it has one (not with ``Penalty``).
        coordinates: node -> coordinates, for every node.
        restrained: nodes whose excitation DOF does not move (fixed, or tied to a fixed
            DOF).
    """

    constraints: tuple[Any, ...]
    checks: tuple[tuple[str, str], ...]
    ndm: int
    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    dofs: tuple[tuple[int, int], ...]
    output_map: np.ndarray
    influence: np.ndarray
    damping_setup: DampingSetup
    opensees_periods: np.ndarray
    coordinates: dict[int, tuple[float, ...]]
    restrained: frozenset[int]

    def periods(self) -> np.ndarray:
        """``[r]`` undamped periods of the linear equations, s, longest first."""
        return 2.0 * np.pi / _frequencies(self.stiffness, self.mass)


def probe(spec: ModelSpec, requested: str, damping: DampingChoice) -> Summary:
    """Choose the constraint handler, set up the damping and read the model's linear
    equations at its gravity state.

    Args:
        spec: the model (its ``constraints`` are ignored).
        requested: ``"auto"`` or a handler name (:data:`.model.HANDLERS`).
        damping: the damping chosen, its factors matched to the modes of the equations at
            the gravity state.

    Raises:
        ScriptError: the script fails, the model cannot be analysed with the requested
            handler (or, with ``"auto"``, with any), or its equations cannot be reduced.
    """
    ops = import_opensees()
    try:
        reference, penalty, checks = _reference(ops, spec)
        if requested == "auto":
            constraints = penalty
            finding = _check(ops, spec, ("Transformation",), reference)
            checks.append(("Transformation", finding or "enforces the constraints"))
            if finding is None:
                constraints = ("Transformation",)
        elif requested == "Penalty":
            constraints = penalty
        else:
            finding = _check(ops, spec, (requested,), reference)
            if finding is not None:
                raise ScriptError(
                    f"constraints = {requested!r} does not work for the model of OpenSees "
                    f"script {spec.script}: {finding}; use constraints = 'auto'"
                )
            checks.append((requested, "enforces the constraints"))
            constraints = (requested,)
        return _summary(ops, spec.with_constraints(constraints), checks, damping)
    finally:
        ops.wipe()


@dataclass(frozen=True)
class _Reference:
    """The exactly constrained model at its gravity state, from the Penalty handler."""

    eigenvalues: np.ndarray
    displacements: dict[int, np.ndarray]


def _reference(ops: Any, spec: ModelSpec) -> tuple[_Reference, tuple[Any, ...], list]:
    """The model analysed with the ``Penalty`` handler (its penalty :data:`PENALTY_FACTOR`
    times the largest diagonal stiffness before gravity) and its equations reduced exactly:
    the reference a handler is checked against, and the Penalty handler's arguments."""
    build_model(ops, spec, gravity=False)
    stiffness, _ = printed_matrix(ops, ("Penalty", 1.0, 1.0), 0.0, 0.0, 1.0)
    constraint, _ = printed_matrix(ops, ("Penalty", 1.0, 1.0), 0.0, 0.0, 0.0)
    scale = float(np.abs(np.diag(stiffness - constraint)).max(initial=0.0)) or 1.0
    alpha = float(f"{PENALTY_FACTOR * scale:.3e}")
    penalty = ("Penalty", alpha, alpha)
    if spec.gravity is not None:
        apply_gravity(ops, spec, penalty)
    reduced = _reduced(ops, spec, assemble(ops, damping=False))
    squares = np.sort(_frequencies(reduced.stiffness, reduced.mass, spec) ** 2)
    reference = _Reference(squares, _all_displacements(ops))
    return reference, penalty, [("Penalty", f"penalty {alpha:.3g}: exact reference")]


def _check(ops: Any, spec: ModelSpec, constraints: tuple[Any, ...], reference: _Reference):
    """None if the handler ``constraints`` brings the model to the reference's gravity
    state and OpenSees' eigen analysis with it finds the reference's eigenvalues; else
    what went wrong, in words."""
    try:
        build_model(ops, spec, constraints)
    except ScriptError as error:
        if spec.gravity is None:
            raise
        return f"its gravity analysis fails ({str(error).splitlines()[0]})"
    displacements = _all_displacements(ops)
    scale = max((np.abs(d).max(initial=0.0) for d in reference.displacements.values()), default=0.0)
    worst = max(
        (
            float(np.abs(displacements[node] - values).max(initial=0.0))
            for node, values in reference.displacements.items()
        ),
        default=0.0,
    )
    if worst > CONSISTENCY * scale + 1e-300 and worst > 0.0:
        return (
            f"its gravity state differs from the exactly constrained model's by "
            f"{worst / scale:.3g} of the largest displacement"
        )
    n = min(CHECKED_MODES, reference.eigenvalues.size)
    try:
        found = np.sort(eigenvalues(ops, constraints, n))
    except RuntimeError as error:
        return f"OpenSees' eigen analysis fails with it ({str(error).splitlines()[0]})"
    expected = reference.eigenvalues[:n]
    difference = np.abs(found[:n] / expected - 1.0)
    if not np.all(np.isfinite(found)) or difference.max() > CONSISTENCY:
        return (
            f"OpenSees' eigen analysis with it finds omega^2 = "
            f"{np.array2string(found[:n], precision=6)}, the exactly constrained model "
            f"{np.array2string(expected, precision=6)}"
        )
    return None


def _summary(
    ops: Any, spec: ModelSpec, checks: list, damping: DampingChoice
) -> Summary:
    """The model analysed to its gravity state with ``spec.constraints`` and read, its
    damping matrix the one its damping commands give there."""
    build_model(ops, spec)
    undamped = _reduced(ops, spec, assemble(ops, damping=False))
    omega = _frequencies(undamped.stiffness, undamped.mass, spec)
    setup = damping.setup(omega, spec.script)
    if setup.kind != "modal":
        setup.apply(ops, tangent=setup.kind == "rayleigh-committed")
    equations = assemble(ops, damping=setup.kind != "modal")
    reduced = _reduced(ops, spec, equations)
    if setup.kind == "modal":
        reduced = replace(reduced, damping=setup.modal_matrix(reduced.mass, reduced.stiffness))
    rows = []
    for node, dof in spec.outputs:
        row = reduced.shapes[equations.equations[(node, dof)]]
        if not np.any(row):
            raise ScriptError(
                f"outputs: DOF {dof} of node {node} of OpenSees script {spec.script} is "
                "restrained: it never moves relative to the ground"
            )
        rows.append(row)
    excitation = np.zeros(equations.size)
    for (_, dof), equation in equations.equations.items():
        if dof == spec.excitation_dof:
            excitation[equation] = 1.0
    load = reduced.shapes.T @ equations.mass @ excitation
    influence = np.linalg.solve(reduced.mass, load)
    influence[np.abs(influence) < 1e-12 * np.abs(influence).max(initial=1.0)] = 0.0
    restrained = frozenset(
        node
        for (node, dof), equation in equations.equations.items()
        if dof == spec.excitation_dof and not np.any(reduced.shapes[equation])
    )
    coordinates = {node: tuple(ops.nodeCoord(node)) for node in ops.getNodeTags()}
    opensees_periods = np.zeros(0)
    if spec.constraints[0] != "Penalty":
        n = min(CHECKED_MODES, omega.size)
        try:
            opensees_periods = 2.0 * np.pi / np.sqrt(eigenvalues(ops, spec.constraints, n))
        except RuntimeError:
            pass
    return Summary(
        constraints=spec.constraints,
        checks=tuple(checks),
        ndm=int(ops.getNDM()[0]),
        mass=reduced.mass,
        damping=reduced.damping,
        stiffness=reduced.stiffness,
        dofs=reduced.dofs,
        output_map=np.asarray(rows),
        influence=influence,
        damping_setup=setup,
        opensees_periods=opensees_periods,
        coordinates=coordinates,
        restrained=restrained,
    )


def _reduced(ops: Any, spec: ModelSpec, equations: Equations):
    """``equations`` reduced (:func:`~..matrices.reduce`), the retained DOFs of the
    model's multi-point constraints kept in preference."""
    prefer = []
    with captured():
        for node in ops.getRetainedNodes():
            for constrained in ops.getConstrainedNodes(node):
                prefer.extend((node, dof) for dof in ops.getRetainedDOFs(node, constrained))
    try:
        return reduce(equations, prefer)
    except ReductionError as error:
        raise ScriptError(
            f"the linear equations of the model of OpenSees script {spec.script} at its "
            f"gravity state cannot be reduced: {error}"
        ) from None


def _frequencies(stiffness: np.ndarray, mass: np.ndarray, spec: ModelSpec | None = None):
    """``[r]`` circular frequencies (rad/s), ascending.

    Raises:
        ScriptError: the stiffness is not positive definite.
    """
    squares = scipy.linalg.eigh(stiffness, mass, eigvals_only=True)
    if squares[0] <= 0.0 or not math.isfinite(squares[0]):
        where = f" of OpenSees script {spec.script}" if spec is not None else ""
        raise ScriptError(
            f"the model{where} is unstable at its gravity state (its stiffness is not "
            f"positive definite: smallest omega^2 = {squares[0]:.3g}): a mechanism, or "
            "gravity loads beyond its buckling load"
        )
    return np.sqrt(squares)


def _all_displacements(ops: Any) -> dict[int, np.ndarray]:
    return {node: np.asarray(ops.nodeDisp(node), dtype=np.float64) for node in ops.getNodeTags()}
