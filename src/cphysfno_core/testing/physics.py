"""Checks that a structure's capabilities describe the same physics as its simulation.

Each check compares two things the structure says about itself against an independent
reference (``scipy.signal.lsim`` for linear responses, ``scipy.linalg.eigh`` for periods),
so that a linear system in the wrong units, with the wrong sign, stiffness or output order,
periods that do not belong to it, a projection that ignores its basis or a coarse step that
does not converge are caught before they make data.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg
import scipy.signal

from ..api.interfaces import Structure
from ..signals import GroundMotions, LinearSystem
from .helpers import fail, smooth_random_motions

SMALL_PEAK = 1e-4
"""Peak output displacement (m) of the linear response at which a structure is taken to
respond elastically: far below any yield displacement of a building or a bridge."""

LINEAR_TOLERANCE = 0.1
"""Relative L2 within which a small-amplitude simulation must follow the exact linear
response. What keeps a correct structure off zero is the time integration of its
simulation (the Example 2 bridge, Newmark's rule with two steps per 0.01 s sample on
piers with short periods: 5-6 %; with one step per sample 14 %, which this check rejects)
and, for reinforced concrete, fibres that crack at strains near 1e-4. A linear system
30 % too stiff, in another unit, with the sign flipped or the outputs in another order
is 0.3 or more away."""

PERIOD_TOLERANCE = 1e-3
"""Relative difference allowed between ``periods()`` and the eigenperiods of
``linear_system()``: both come from the same matrices, up to the solver's round-off."""

TANGENT_TOLERANCE = 1e-3
"""Relative (Frobenius) difference allowed between the restoring force's tangent at rest,
by central differences, and the linear system's stiffness."""

PROJECTION_TOLERANCE = 1e-2
"""Relative L2 within which ``simulate_projected`` with the full identity basis must follow
``simulate`` on yielding records: the two may integrate with different schemes and steps."""

YIELD_DEVIATION = 0.05
"""Relative L2 from the linear response at which a record is taken to yield the structure."""


def motions(n_steps: int = 501, dt: float = 0.01, n_records: int = 2) -> GroundMotions:
    """Smooth random accelerations of unit peak (m/s^2), 5 s at 0.01 s by default."""
    return smooth_random_motions(n_records, n_steps, dt, peak=1.0, seed=7, window=7)


def linear_response(system: LinearSystem, ground: GroundMotions) -> np.ndarray:
    """``[n, T, n_outputs]`` exact response (m) of ``system`` from rest, the ground
    acceleration linear between samples (``scipy.signal.lsim``)."""
    a, b = system.state_space()
    output = np.hstack([system.output_map, np.zeros_like(system.output_map)])
    model = scipy.signal.StateSpace(a, b[:, None], output, np.zeros((output.shape[0], 1)))
    return np.stack(
        [
            scipy.signal.lsim(model, record, ground.time)[1].reshape(ground.n_steps, -1)
            for record in ground.acceleration
        ]
    )


def relative_l2(value: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Relative L2 per output of ``[n, T, dof]`` arrays over records and time."""
    error = np.sqrt(np.sum((value - reference) ** 2, axis=(0, 1)))
    return error / np.maximum(np.sqrt(np.sum(reference**2, axis=(0, 1))), 1e-300)


def scaled(ground: GroundMotions, factor: float) -> GroundMotions:
    return GroundMotions(ground.acceleration * factor, ground.dt)


def physics_checks(structure: Structure) -> list[Callable[[Structure], None]]:
    """The checks of this module that ``structure``'s capabilities call for: with
    ``linear_system``, its periods and small-amplitude response, and where declared its
    restoring force's tangent and its projected simulation; with ``coarse_simulation``, a
    coarse step's convergence."""
    capabilities = structure.capabilities
    checks: list[Callable[[Structure], None]] = []
    if "linear_system" in capabilities:
        checks += [check_periods_are_eigenperiods, check_small_amplitude_is_linear]
        if "restoring_force" in capabilities:
            checks.append(check_tangent_at_rest)
        if "projected_simulation" in capabilities:
            checks.append(check_projected_simulation)
    if "coarse_simulation" in capabilities:
        checks.append(check_coarse_convergence)
    return checks


def _linear(structure: Structure) -> tuple[LinearSystem, GroundMotions, np.ndarray, float]:
    """The structure's linear system, the check's motions, their exact linear response
    ``[n, T, n_outputs]`` (m) and the scale of the motions at which it peaks at
    :data:`SMALL_PEAK`."""
    system = structure.linear_system()
    ground = motions()
    reference = linear_response(system, ground)
    return system, ground, reference, SMALL_PEAK / np.max(np.abs(reference))


def check_periods_are_eigenperiods(structure: Structure) -> None:
    """``periods()`` are the eigenperiods of ``linear_system()``'s ``(K, M)``."""
    system = structure.linear_system()
    squares = scipy.linalg.eigh(system.stiffness, system.mass, eigvals_only=True)
    expected = 2 * np.pi / np.sqrt(np.sort(squares))
    claimed = np.asarray(structure.periods(), dtype=float)
    n = min(len(claimed), len(expected), 3)
    difference = np.abs(claimed[:n] / expected[:n] - 1.0)
    if not (difference <= PERIOD_TOLERANCE).all():
        raise fail(
            structure,
            f"periods() {np.round(claimed[:n], 4).tolist()} s are not the eigenperiods "
            f"{np.round(expected[:n], 4).tolist()} s of its linear_system()",
        )


def check_small_amplitude_is_linear(structure: Structure) -> None:
    """At an amplitude far below yield, ``simulate`` is the response of
    ``linear_system()``: same units, sign, stiffness and output order."""
    _, ground, reference, small = _linear(structure)
    simulated = structure.simulate(scaled(ground, small)).displacement / small
    error = relative_l2(simulated, reference)
    if (error <= LINEAR_TOLERANCE).all():
        return
    worst = int(np.argmax(error))
    ratio = np.linalg.norm(simulated[..., worst]) / np.linalg.norm(reference[..., worst])
    correlation = np.sum(simulated[..., worst] * reference[..., worst]) / (
        np.linalg.norm(simulated[..., worst]) * np.linalg.norm(reference[..., worst]) + 1e-300
    )
    hints = []
    if ratio > 10 or ratio < 0.1:
        hints.append(f"its amplitude is {ratio:.3g} times the linear one: units?")
    if correlation < -0.5:
        hints.append("it runs against the linear one: sign?")
    matches = [
        o
        for o in range(reference.shape[2])
        if relative_l2(simulated[..., worst : worst + 1], reference[..., o : o + 1])[0]
        <= LINEAR_TOLERANCE
    ]
    if matches and matches[0] != worst:
        hints.append(f"it is the linear system's output {matches[0]}: output order?")
    raise fail(
        structure,
        f"at small amplitude simulate() is {error[worst]:.3g} (relative L2) from the exact "
        f"response of its linear_system() at output {worst} ({structure.output_names[worst]})"
        + (": " + "; ".join(hints) if hints else ": stiffness, mass or damping differ"),
    )


def check_tangent_at_rest(structure: Structure) -> None:
    """The tangent at rest of ``restoring_force()`` (through its internal state where it
    has one) is the stiffness of ``linear_system()``."""
    system = structure.linear_system()
    force = structure.restoring_force()
    n = system.n_dof
    state = force.initial_state(1)
    step = SMALL_PEAK
    tangent = np.empty((n, n))
    for j in range(n):
        unit = np.zeros((1, n))
        unit[0, j] = 1.0
        direct = (force.force(step * unit, state) - force.force(-step * unit, state)) / (2 * step)
        rate = force.state_rate(np.zeros((1, n)), unit, state)  # state change per unit u_j
        through_state = np.zeros((1, n))
        for s in np.flatnonzero(rate[0]):
            shift = np.zeros_like(state)
            shift[0, s] = step
            slope = (
                force.force(np.zeros((1, n)), state + shift)
                - force.force(np.zeros((1, n)), state - shift)
            ) / (2 * step)
            through_state += slope * rate[0, s]
        tangent[:, j] = (direct + through_state)[0]
    difference = np.linalg.norm(tangent - system.stiffness) / np.linalg.norm(system.stiffness)
    if difference > TANGENT_TOLERANCE:
        raise fail(
            structure,
            f"the tangent of restoring_force() at rest is {difference:.3g} (relative) from "
            "linear_system().stiffness",
        )


def yielding_motions(
    structure: Structure, ground: GroundMotions, reference: np.ndarray, small: float
) -> GroundMotions:
    """``ground`` scaled by powers of 4 from ``small`` until ``simulate`` leaves the linear
    response by :data:`YIELD_DEVIATION` (the last scale tried if it never does)."""
    factor = small
    for _ in range(10):
        factor *= 4.0
        simulated = structure.simulate(scaled(ground, factor)).displacement / factor
        if relative_l2(simulated, reference).max() > YIELD_DEVIATION:
            break
    return scaled(ground, factor)


def check_projected_simulation(structure: Structure) -> None:
    """``simulate_projected`` with the full basis is ``simulate`` on yielding records, and
    with the first mode alone at small amplitude is the one-mode linear response."""
    system, ground, reference, small = _linear(structure)
    yielding = yielding_motions(structure, ground, reference, small)
    n = system.n_dof
    full = structure.simulate_projected(yielding, np.eye(n)).displacement
    truth = structure.simulate(yielding).displacement
    error = relative_l2(full, truth).max()
    if error > PROJECTION_TOLERANCE:
        raise fail(
            structure,
            f"simulate_projected() with the full basis is {error:.3g} (relative L2) from "
            "simulate() on yielding records",
        )
    _, shapes = scipy.linalg.eigh(system.stiffness, system.mass, subset_by_index=(0, 0))
    mode = shapes[:, :1]
    reduced = LinearSystem(
        mode.T @ system.mass @ mode,
        mode.T @ system.damping @ mode,
        mode.T @ system.stiffness @ mode,
        np.linalg.solve(mode.T @ system.mass @ mode, mode.T @ system.mass @ system.influence),
        system.output_map @ mode,
    )
    expected = linear_response(reduced, ground)
    projected = structure.simulate_projected(scaled(ground, small), mode).displacement / small
    error = relative_l2(projected, expected).max()
    if error > LINEAR_TOLERANCE:
        raise fail(
            structure,
            f"simulate_projected() on the first mode is {error:.3g} (relative L2) from the "
            "one-mode linear response at small amplitude: does it use its basis?",
        )


def check_coarse_convergence(structure: Structure) -> None:
    """``simulate(dt=k dt)`` comes closer to the fine response as ``k`` falls (k = 6
    against k = 2), on records that yield the structure where it has a linear system to
    tell (:func:`yielding_motions`)."""
    ground = motions()
    if "linear_system" in structure.capabilities:
        ground = yielding_motions(structure, *_linear(structure)[1:])
    fine = structure.simulate(ground).displacement
    errors = {}
    for k in (2, 6):
        coarse = structure.simulate(ground, dt=k * ground.dt).displacement
        samples = fine[:, ::k]
        length = min(coarse.shape[1], samples.shape[1])
        errors[k] = relative_l2(coarse[:, :length], samples[:, :length]).max()
    if not errors[2] < errors[6]:
        raise fail(
            structure,
            f"a coarse step does not converge to the fine response: {errors[2]:.3g} "
            f"(relative L2) at 2 dt, {errors[6]:.3g} at 6 dt",
        )
