"""The SAC frame while none of its steel yields: an exact linear model of nine DOFs.

While every fibre of the fibre model stays on the elastic branch of its bilinear steel, the
OpenSees model is linear (elastic interior sections, the leaning column's linear springs;
only the P-Delta effect of the columns' own axial forces, zero at rest, is of second
order). Its rotations and vertical displacements carry no mass and its damping is Rayleigh
on the mass and the initial stiffness, so the floors obey a nine-DOF model exactly: from
rest, every DOF is a fixed linear function of the floor displacements at every Newmark
step; after a yield, the floors obey the same model offset by the restoring force at the
step the phase began. :func:`elastic_frame` builds that model from nine static analyses of
the OpenSees model under a unit load at each floor; :func:`newmark_floors` integrates it
with the same Newmark rule as the OpenSees analysis, in milliseconds instead of seconds;
:func:`first_step_beyond` finds the first step at which a fibre leaves a given share of its
elastic range (:func:`fibre_centres`); :func:`set_state` hands the state back to OpenSees.
:func:`cphysfno_opensees.sac9.analysis.analyse_record` runs OpenSees only between such
phases, and not at all for a record that never yields.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from cphysfno_core.plugin import Rayleigh

from ..loader import import_opensees
from .interior import InteriorSections
from .model import Frame, FrameConfig, build_frame
from .sections import HARDENING_RATIO, N_STORIES, STEEL_MODULUS

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
        sections: ``(element, integration point)`` of every fibre section, in the order
            of the fibres below.
        interior: the elastic interior sections (:class:`InteriorSections`), whose
            outermost fibres follow those of the fibre sections below.
        stress_map: ``[n, 9]`` elastic stress (Pa per metre of floor displacement) of every
            fibre of the fibre sections, then of the two outermost fibres of every elastic
            interior section (where a fibre section would first yield).
        yield_stress: ``[n]`` the yield stress of those fibres, Pa.
        outermost: ``[n]`` whether a fibre is an outermost one of a section at a member's
            end, where the stress from rest is largest (the moment is linear along a
            member without loads between its ends).
    """

    masses: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    node_map: dict[int, np.ndarray]
    sections: tuple[tuple[int, int], ...]
    interior: InteriorSections
    stress_map: np.ndarray
    yield_stress: np.ndarray
    outermost: np.ndarray


@functools.lru_cache(maxsize=4)
def elastic_frame(config: FrameConfig, damping: Rayleigh) -> ElasticFrame:
    """The condensed model of ``config`` (fibre model), with Rayleigh ``damping`` on the
    mass and the initial stiffness; computed once per process, model and damping.

    OpenSees leaves zero-length elements out of Rayleigh damping, so the damping is
    proportional to the stiffness of the model without the leaning column's springs (which
    join floors only and so do not change how the massless DOFs follow the floors).

    Raises:
        ValueError: ``config`` is not the fibre model.
    """
    if config.model != "fibre":
        raise ValueError(f"the condensed elastic model needs the fibre model, not {config.model!r}")
    flexibility, nodes, fibres, masses = _unit_load_responses(config)
    stiffness = _symmetric_inverse(flexibility)
    return ElasticFrame(
        masses=masses,
        stiffness=stiffness,
        damping=damping.matrix(np.diag(masses), _damped_stiffness(config, stiffness)),
        node_map={node: unit @ stiffness for node, unit in nodes.items()},
        sections=fibres.sections,
        interior=fibres.interior,
        stress_map=fibres.stress @ stiffness,
        yield_stress=fibres.yield_stress,
        outermost=fibres.outermost,
    )


@functools.lru_cache(maxsize=4)
def condensed_system(
    config: FrameConfig, damping: Rayleigh
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(masses [9] kg, stiffness [9, 9] N/m, damping [9, 9] N s/m)`` of the model of
    ``config`` (fibre or hinges) condensed to its floors' horizontal displacements while it
    is elastic, from unit loads at each floor, P-Delta included as the model has it; the
    damping as :func:`elastic_frame`'s. Computed once per process, model and damping."""
    flexibility, _, _, masses = _unit_load_responses(config, with_fibres=False)
    stiffness = _symmetric_inverse(flexibility)
    return masses, stiffness, damping.matrix(np.diag(masses), _damped_stiffness(config, stiffness))


def _damped_stiffness(config: FrameConfig, stiffness: np.ndarray) -> np.ndarray:
    """The condensed stiffness the Rayleigh damping is proportional to: without P-Delta's
    leaning-column springs, which OpenSees leaves out of Rayleigh damping."""
    if not config.p_delta:
        return stiffness
    plain = dataclasses.replace(config, p_delta=False)
    return _symmetric_inverse(_unit_load_responses(plain, with_fibres=False)[0])


def _symmetric_inverse(flexibility: np.ndarray) -> np.ndarray:
    stiffness = np.linalg.inv(flexibility)
    return 0.5 * (stiffness + stiffness.T)


def _unit_load_responses(
    config: FrameConfig, with_fibres: bool = True
) -> tuple[np.ndarray, dict[int, np.ndarray], _Fibres | None, np.ndarray]:
    """Responses of the model to a unit horizontal load at each floor in turn: the
    ``[9, 9]`` floor flexibility (m/N), every node's ``[3, 9]`` displacements, the fibres'
    ``[n, 9]`` stresses (Pa/N; None without ``with_fibres``), and the ``[9]`` floor masses
    (kg)."""
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
            if with_fibres:
                fibres = _fibres(ops, frame, config)
                stresses.append(fibres.stress / UNIT_LOAD)
    finally:
        ops.wipe()
    if not with_fibres:
        return flexibility, nodes, None, frame.masses.copy()
    fibres = dataclasses.replace(fibres, stress=np.stack(stresses, axis=1))
    return flexibility, nodes, fibres, frame.masses.copy()


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


@dataclass(frozen=True)
class _Fibres:
    sections: tuple[tuple[int, int], ...]
    interior: InteriorSections
    stress: np.ndarray
    yield_stress: np.ndarray
    outermost: np.ndarray


def _fibres(ops: Any, frame: Frame, config: FrameConfig) -> _Fibres:
    """The fibres of every fibre section (elements in tag order, points in order), then
    the outermost fibres of the elastic interior sections: their stresses now, yield
    stresses, and which are the outermost ones at a member's end."""
    sections, stress, limit, outermost = [], [], [], []
    for element, member in sorted(frame.members.items()):
        fy = member.yield_stress
        n_points = len(ops.eleResponse(element, "integrationPoints"))
        for point in range(1, n_points + 1):
            fibres = np.reshape(ops.eleResponse(element, "section", point, "fiberData"), (-1, 5))
            if not fibres.size:
                continue
            sections.append((element, point))
            stress.extend(fibres[:, 3])
            limit.extend([fy] * len(fibres))
            depth = np.abs(fibres[:, 0])
            end = point in (1, n_points)
            outermost.extend(end & (depth >= depth.max() * (1 - 1e-12)))
    interior = InteriorSections.of(frame, config)
    stress.extend(interior.stresses(ops))
    limit.extend(np.repeat(interior.yield_stress, 2))
    outermost.extend([False] * 2 * len(interior.sections))
    return _Fibres(
        tuple(sections), interior, np.asarray(stress), np.asarray(limit), np.asarray(outermost)
    )


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
    """Floor response of the condensed model from rest under ``acceleration [T]`` (m/s^2)
    at ``dt`` (s), one step per sample, as the OpenSees analysis integrates it (it, too,
    starts with zero relative acceleration whatever the first sample).

    Returns:
        ``[T, 9]`` displacements (m), velocities (m/s) and accelerations (m/s^2).
    """
    loads = -np.outer(np.asarray(acceleration, dtype=float), frame.masses)
    rest = np.zeros(frame.masses.size)
    return newmark_floors(frame, loads, dt, FloorState(rest, rest, rest))


def newmark_floors(
    frame: ElasticFrame, loads: np.ndarray, dt: float, initial: FloorState
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``M u'' + C u' + K u = P`` by Newmark's average acceleration rule.

    Args:
        frame: the condensed model (M, C, K).
        loads: ``[T, 9]`` floor loads P at every step, N (row 0 is not used).
        dt: time step, s.
        initial: the state at row 0.

    Returns:
        ``[T, 9]`` displacements (m), velocities (m/s) and accelerations (m/s^2); row 0 is
        ``initial``.
    """
    n = frame.masses.size
    mass = np.diag(frame.masses)
    solve = np.linalg.inv(frame.stiffness + 2.0 / dt * frame.damping + 4.0 / dt**2 * mass)
    # State s = (u, v, a): s_{k+1} = A s_k + B P_{k+1}.
    zero, eye = np.zeros((n, n)), np.eye(n)
    new_u = solve @ np.hstack(
        [4.0 / dt**2 * mass + 2.0 / dt * frame.damping, 4.0 / dt * mass + frame.damping, mass]
    )
    u_part, v_part, a_part = (
        np.hstack([eye, zero, zero]),
        np.hstack([zero, eye, zero]),
        np.hstack([zero, zero, eye]),
    )
    transition = np.vstack(
        [
            new_u,
            2.0 / dt * (new_u - u_part) - v_part,
            4.0 / dt**2 * (new_u - u_part) - 4.0 / dt * v_part - a_part,
        ]
    )
    forced = (
        np.asarray(loads, dtype=float) @ np.vstack([solve, 2.0 / dt * solve, 4.0 / dt**2 * solve]).T
    )
    states = np.empty((len(forced), 3 * n))
    state = np.concatenate([initial.displacement, initial.velocity, initial.acceleration])
    states[0] = state
    transition_t = transition.T.copy()
    for k in range(1, len(forced)):
        state = state @ transition_t + forced[k]
        states[k] = state
    return states[:, :n], states[:, n : 2 * n], states[:, 2 * n :]


def first_step_beyond(
    frame: ElasticFrame,
    displacement: np.ndarray,
    share: float,
    centres: np.ndarray | None = None,
) -> int | None:
    """First row of ``displacement`` at which a fibre leaves ``share`` of its elastic range.

    Args:
        frame: the condensed model.
        displacement: ``[T, 9]`` floor displacements (m) from the state ``centres``
            describe.
        share: share of the yield stress.
        centres: ``[n]`` the fibres' elastic centres (:func:`fibre_centres`), Pa: a fibre
            stays elastic while ``|centre + stress increment|`` is below its yield stress;
            None: from rest, where the outermost fibres at the members' ends decide.

    Returns:
        The row, or None if every fibre stays within ``share`` of its range throughout.
    """
    rows = frame.outermost if centres is None else slice(None)
    stress_map = frame.stress_map[rows]
    limit = share * frame.yield_stress[rows]
    margin = limit - (0.0 if centres is None else np.abs(centres))
    magnitude = np.abs(stress_map)
    for start in range(0, len(displacement), ROWS_PER_CHECK):
        block = displacement[start : start + ROWS_PER_CHECK]
        # Only fibres whose margin the block's largest floor displacements could use up.
        candidates = np.flatnonzero(magnitude @ np.abs(block).max(axis=0) >= margin)
        if not candidates.size:
            continue
        centre = 0.0 if centres is None else centres[candidates]
        stress = centre + block @ stress_map[candidates].T
        reached = np.flatnonzero((np.abs(stress) >= limit[candidates]).any(axis=1))
        if reached.size:
            return start + int(reached[0])
    return None


ROWS_PER_CHECK = 32
"""Steps checked at a time by :func:`first_step_beyond`, which stops at the first block
with a fibre out of range."""


def fibre_centres(ops: Any, frame: ElasticFrame) -> np.ndarray:
    """``[n]`` elastic centres (:func:`elastic_centre`) of the fibres of the OpenSees model
    now, Pa; for the outermost fibres of elastic interior sections, their stresses."""
    data = np.concatenate(
        [
            np.reshape(ops.eleResponse(element, "section", point, "fiberData"), (-1, 5))
            for element, point in frame.sections
        ]
    )
    return np.concatenate([elastic_centre(data[:, 3], data[:, 4]), frame.interior.stresses(ops)])


def elastic_centre(stress: np.ndarray, strain: np.ndarray) -> np.ndarray:
    """Where the elastic range of the frame's steel (``Steel01``, kinematic hardening) is
    centred, in stress (Pa), for fibres at ``stress`` (Pa) and ``strain``.

    ``Steel01`` stays elastic while ``|sigma - b E epsilon| < (1 - b) F_y``; while it does,
    the stress changes by ``E`` times the strain increment, so a fibre stays elastic while
    ``|centre + E * strain increment| < F_y`` with ``centre = (sigma - b E epsilon) / (1 - b)``.
    """
    b = HARDENING_RATIO
    return (np.asarray(stress) - b * STEEL_MODULUS * np.asarray(strain)) / (1.0 - b)


def set_state(
    ops: Any,
    frame: ElasticFrame,
    state: FloorState,
    base: dict[int, np.ndarray] | None = None,
) -> None:
    """Set every node of the (built) OpenSees model to the displacements, velocities and
    accelerations the condensed model gives for the floors' ``state``, committed.

    Args:
        base: every node's ``[3]`` displacements from which ``state.displacement`` is
            measured; None: from rest.
    """
    for node, unit in frame.node_map.items():
        displacement = unit @ state.displacement
        if base is not None:
            displacement = displacement + base[node]
        velocity, acceleration = unit @ state.velocity, unit @ state.acceleration
        for dof in range(3):
            ops.setNodeDisp(node, dof + 1, float(displacement[dof]), "-commit")
            ops.setNodeVel(node, dof + 1, float(velocity[dof]), "-commit")
            ops.setNodeAccel(node, dof + 1, float(acceleration[dof]), "-commit")
