"""The SAC frame while none of its steel has yielded: an exact linear model of nine DOFs.

Until the first fibre of the fibre model reaches its yield stress, the OpenSees model is
linear (bilinear steel on its elastic branch, elastic interior sections, the leaning
column's linear springs; only the P-Delta effect of the columns' own axial forces, which
are zero at rest, is of second order). Its rotations and vertical displacements carry no
mass and its damping is Rayleigh on the mass and the initial stiffness, so every DOF is a
fixed linear function of the nine floor displacements at every Newmark step from rest:
the whole model condenses exactly to the floors. :func:`elastic_frame` builds that
condensed model from nine static analyses of the OpenSees model under a unit load at each
floor; :func:`elastic_response` integrates it with the same Newmark rule as the OpenSees
analysis, in milliseconds instead of seconds; :func:`first_yield_step` finds the first
step at which a fibre would reach a given share of its yield stress. The analysis of a
record (:func:`cphysfno_opensees.sac9_analysis.analyse_record`) takes the response up to
there from this model and starts OpenSees from its state, or needs no OpenSees at all for
a record that never yields.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from .loader import import_opensees
from .sac9_model import FrameConfig, build_frame
from .sac9_sections import N_STORIES

UNIT_LOAD = 1.0e5
"""Floor load of the static analyses, N (the model is linear; the size only keeps the
element iterations away from round-off)."""


@dataclass(frozen=True)
class ElasticFrame:
    """The frame condensed to its floors while every fibre is elastic.

    Attributes:
        masses: ``[9]`` floor masses, kg.
        stiffness: ``[9, 9]`` lateral stiffness of the floors, N/m.
        damping: ``[9, 9]`` Rayleigh damping condensed to the floors, N s/m.
        node_map: every node's ``[3, 9]`` displacements (m, rad) per metre of each floor
            displacement, keyed by node tag.
        stress_map: ``[n, 9]`` stress (Pa per metre of floor displacement) of the
            outermost fibres of the sections at both ends of every member, where the
            moment, linear along a member without loads between its ends, is largest.
        yield_stress: ``[n]`` the yield stress of those fibres, Pa.
    """

    masses: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    node_map: dict[int, np.ndarray]
    stress_map: np.ndarray
    yield_stress: np.ndarray


@functools.lru_cache(maxsize=4)
def elastic_frame(
    config: FrameConfig, mass_damping: float, stiffness_damping: float
) -> ElasticFrame:
    """The condensed model of ``config`` (fibre model), with Rayleigh coefficients on the
    mass (1/s) and the initial stiffness (s); computed once per process and model.

    OpenSees leaves zero-length elements out of Rayleigh damping, so the damping is
    proportional to the stiffness of the model without the leaning column's springs (which
    join floors only and so do not change how the massless DOFs follow the floors).

    Raises:
        ValueError: ``config`` is not the fibre model.
    """
    if config.model != "fibre":
        raise ValueError(f"the condensed elastic model needs the fibre model, not {config.model!r}")
    flexibility, nodes, stresses, limits, masses = _unit_load_responses(config)
    stiffness = _symmetric_inverse(flexibility)
    damped = stiffness
    if config.p_delta:
        damped = _symmetric_inverse(
            _unit_load_responses(dataclasses.replace(config, p_delta=False))[0]
        )
    return ElasticFrame(
        masses=masses,
        stiffness=stiffness,
        damping=mass_damping * np.diag(masses) + stiffness_damping * damped,
        node_map={node: unit @ stiffness for node, unit in nodes.items()},
        stress_map=stresses @ stiffness,
        yield_stress=limits,
    )


def _symmetric_inverse(flexibility: np.ndarray) -> np.ndarray:
    stiffness = np.linalg.inv(flexibility)
    return 0.5 * (stiffness + stiffness.T)


def _unit_load_responses(
    config: FrameConfig,
) -> tuple[np.ndarray, dict[int, np.ndarray], np.ndarray, np.ndarray, np.ndarray]:
    """Responses of the model to a unit horizontal load at each floor in turn: the
    ``[9, 9]`` floor flexibility (m/N), every node's ``[3, 9]`` displacements, the
    ``[n, 9]`` stresses of the end sections' outermost fibres (Pa/N), their ``[n]`` yield
    stresses (Pa), and the ``[9]`` floor masses (kg)."""
    ops = import_opensees()
    n_floors = N_STORIES
    flexibility = np.zeros((n_floors, n_floors))
    nodes: dict[int, np.ndarray] = {}
    stresses: list[np.ndarray] = []
    try:
        for j in range(n_floors):
            frame = build_frame(ops, config)
            _unit_load_analysis(ops, frame.floors[j])
            flexibility[:, j] = [ops.nodeDisp(node, 1) / UNIT_LOAD for node in frame.floors]
            for node in ops.getNodeTags():
                unit = np.asarray(ops.nodeDisp(node)) / UNIT_LOAD
                nodes.setdefault(node, np.zeros((3, n_floors)))[:, j] = unit
            stress, limits = _end_fibre_stresses(ops, frame.yield_stresses)
            stresses.append(stress / UNIT_LOAD)
    finally:
        ops.wipe()
    return flexibility, nodes, np.stack(stresses, axis=1), limits, frame.masses.copy()


def _unit_load_analysis(ops: Any, floor: int) -> None:
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(floor, UNIT_LOAD, 0.0, 0.0)
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-14, 5)
    ops.algorithm("Linear")
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    if ops.analyze(1) != 0:
        raise RuntimeError(f"the static analysis under a load at node {floor} failed")


def _end_fibre_stresses(
    ops: Any, yield_stresses: dict[int, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Stresses of the outermost fibres at both ends of every member, and their yield
    stresses, in element-tag order."""
    stress, limit = [], []
    for element, fy in sorted(yield_stresses.items()):
        n_points = len(ops.eleResponse(element, "integrationPoints"))
        for point in (1, n_points):
            data = np.asarray(ops.eleResponse(element, "section", point, "fiberData"))
            fibres = data.reshape(-1, 5)
            outermost = np.abs(fibres[:, 0]) >= np.abs(fibres[:, 0]).max() * (1 - 1e-12)
            stress.extend(fibres[outermost, 3])
            limit.extend([fy] * int(outermost.sum()))
    return np.asarray(stress), np.asarray(limit)


@dataclass(frozen=True)
class FloorState:
    """Newmark state of the floors at one step: ``[9]`` displacements (m), velocities
    (m/s) and accelerations (m/s^2) relative to the ground."""

    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def elastic_response(
    frame: ElasticFrame, acceleration: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Floor response of the condensed model from rest, by Newmark's average acceleration
    rule at ``dt``, one step per sample, as the OpenSees analysis integrates it (it, too,
    starts with zero relative acceleration whatever the first sample).

    Args:
        frame: the condensed model.
        acceleration: ``[T]`` ground acceleration, m/s^2.
        dt: time step, s.

    Returns:
        ``[T, 9]`` displacements (m), velocities (m/s) and accelerations (m/s^2).
    """
    n = frame.masses.size
    mass = np.diag(frame.masses)
    effective = frame.stiffness + 2.0 / dt * frame.damping + 4.0 / dt**2 * mass
    solve = np.linalg.inv(effective)
    # s_{k+1} = A s_k + b a_g[k+1] for the state s = (u, v, a).
    history = np.hstack(
        [4.0 / dt**2 * mass + 2.0 / dt * frame.damping, 4.0 / dt * mass + frame.damping, mass]
    )
    new_u = solve @ history
    eye = np.eye(n)
    shift = np.hstack([eye, np.zeros((n, 2 * n))])
    new_v = 2.0 / dt * (new_u - shift) - np.hstack([np.zeros((n, n)), eye, np.zeros((n, n))])
    new_a = (
        4.0 / dt**2 * (new_u - shift)
        - 4.0 / dt * np.hstack([np.zeros((n, n)), eye, np.zeros((n, n))])
        - np.hstack([np.zeros((n, 2 * n)), eye])
    )
    transition = np.vstack([new_u, new_v, new_a])
    load_u = -solve @ frame.masses
    load = np.concatenate([load_u, 2.0 / dt * load_u, 4.0 / dt**2 * load_u])
    states = np.zeros((acceleration.size, 3 * n))
    state = np.zeros(3 * n)
    transition_t = transition.T.copy()
    for k in range(1, acceleration.size):
        state = state @ transition_t + acceleration[k] * load
        states[k] = state
    return states[:, :n], states[:, n : 2 * n], states[:, 2 * n :]


def first_yield_step(frame: ElasticFrame, displacement: np.ndarray, share: float) -> int | None:
    """First step at which a fibre's elastic stress reaches ``share`` of its yield stress
    under floor displacements ``displacement [T, 9]`` (m); None if none does."""
    ratio = np.abs(displacement @ frame.stress_map.T) / frame.yield_stress
    reached = np.flatnonzero(ratio.max(axis=1) >= share)
    return int(reached[0]) if reached.size else None


def set_state(ops: Any, frame: ElasticFrame, state: FloorState) -> None:
    """Set every node of the (built) OpenSees model to the displacements, velocities and
    accelerations the condensed model gives for ``state``, committed."""
    for node, unit in frame.node_map.items():
        for dof, (u, v, a) in enumerate(
            zip(
                unit @ state.displacement,
                unit @ state.velocity,
                unit @ state.acceleration,
                strict=True,
            ),
            start=1,
        ):
            ops.setNodeDisp(node, dof, float(u), "-commit")
            ops.setNodeVel(node, dof, float(v), "-commit")
            ops.setNodeAccel(node, dof, float(a), "-commit")
