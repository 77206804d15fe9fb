"""Physics checks of a story law: call :func:`check_story_law` from a law plugin's tests.

The law is driven through drift histories by integrating its rate form with short steps
(classical Runge-Kutta in time along a drift path linear within each step, ``settle`` after
each step), the way the shear-building integrator uses it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..api.story_law import LawFunctions, StoryLaw

TANGENT_TOLERANCE = 1e-3
"""Relative difference allowed between the tangent at rest and the story stiffness."""

RATE_TOLERANCE = 1e-6
"""Relative difference allowed between the loops of one drift path at two speeds."""

ENERGY_TOLERANCE = 1e-6
"""Negative dissipated energy allowed over closed cycles, relative to ``k u_y^2``."""


def _fail(law: Any, message: str) -> AssertionError:
    return AssertionError(f"story law '{getattr(law, 'name', type(law).__name__)}': {message}")


def drive(
    functions: LawFunctions,
    n_states: int,
    coefficients: np.ndarray,
    drift: np.ndarray,
    duration: float = 1.0,
    substeps: int = 4,
) -> np.ndarray:
    """Story shears (N) of one story along a drift history.

    Args:
        functions: the law's compiled functions.
        n_states: the law's state variables.
        coefficients: ``[n_c]`` the story's coefficients.
        drift: ``[T]`` drift samples (m), linear between them.
        duration: seconds the whole history takes (a rate-independent law ignores it).
        substeps: Runge-Kutta steps between samples.

    Returns:
        ``[T]`` story shears at the samples.
    """
    force, rate, settle = functions
    c = np.ascontiguousarray(coefficients, dtype=np.float64)
    width = max(n_states, 1)
    state = np.zeros(width)
    out = np.zeros(width)
    drift = np.asarray(drift, dtype=np.float64)
    h = duration / (len(drift) - 1) / substeps
    shear = np.empty(len(drift))
    shear[0] = force(c, drift[0], state)
    for k in range(len(drift) - 1):
        speed = (drift[k + 1] - drift[k]) / (h * substeps)
        for sub in range(substeps):
            v0 = drift[k] + speed * h * sub
            slopes = []
            stage = state.copy()
            for fraction, advance in ((0.0, 0.5), (0.5, 0.5), (0.5, 1.0), (1.0, 0.0)):
                out[:] = 0.0
                rate(c, v0 + speed * h * fraction, speed, stage, out)
                slopes.append(out.copy())
                stage = state + advance * h * out
            state = state + h * (slopes[0] + 2 * slopes[1] + 2 * slopes[2] + slopes[3]) / 6.0
            settle(c, v0 + speed * h, state)
        shear[k + 1] = force(c, drift[k + 1], state)
    return shear


def cyclic_drift(amplitude: float, cycles: int = 3, per_cycle: int = 400) -> np.ndarray:
    """``[cycles * per_cycle + 1]`` drifts (m) of cycles growing to ``amplitude``."""
    t = np.linspace(0.0, cycles, cycles * per_cycle + 1)
    return amplitude * (t / cycles) * np.sin(2.0 * np.pi * t)


def _yield_drift(law: StoryLaw) -> float:
    """The first story's yield drift (m), 0.01 m for a law without one."""
    yield_drift = law.yield_drift(3)
    return 0.01 if yield_drift is None else float(yield_drift[0])


def _first_story(law: StoryLaw, stiffness: float) -> tuple[LawFunctions, np.ndarray]:
    """The law's functions and the coefficients of a story of ``stiffness`` (N/m)."""
    return law.functions(), law.coefficients(np.full(3, stiffness))[0]


def _loops(law: StoryLaw, stiffness: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cycles growing to 4 times the yield drift: the drift path (m) and the shears (N) when
    it takes 10 s and 0.1 s."""
    functions, c = _first_story(law, stiffness)
    path = cyclic_drift(4.0 * _yield_drift(law))
    slow = drive(functions, law.n_states, c, path, duration=10.0)
    fast = drive(functions, law.n_states, c, path, duration=0.1)
    if not (np.all(np.isfinite(slow)) and np.all(np.isfinite(fast))):
        raise _fail(law, "its shear is not finite under cycles of 4 times the yield drift")
    return path, slow, fast


def check_declarations(law: StoryLaw, stiffness: float = 1.0e7) -> None:
    """``state_names`` names every state variable, the coefficients of ``d`` stories come
    as a float64 ``[d, n_c]`` array, and ``functions()`` as
    :class:`~cphysfno_core.LawFunctions`."""
    if len(law.state_names) != law.n_states:
        raise _fail(law, f"state_names names {len(law.state_names)} of {law.n_states} states")
    coefficients = law.coefficients(np.full(3, stiffness))
    if not (
        isinstance(coefficients, np.ndarray)
        and coefficients.ndim == 2
        and coefficients.shape[0] == 3
        and coefficients.dtype == np.float64
    ):
        raise _fail(law, "coefficients(stiffness [d]) must be a float64 [d, n_c] array")
    if not isinstance(law.functions(), LawFunctions):
        raise _fail(law, "functions() must return cphysfno_core.LawFunctions")


def check_at_rest(law: StoryLaw, stiffness: float = 1.0e7) -> None:
    """At rest the shear is zero and its tangent is the story stiffness (within
    :data:`TANGENT_TOLERANCE`), which the building's linear system assumes."""
    functions, c = _first_story(law, stiffness)
    small = 1e-6 * _yield_drift(law)
    at_rest = drive(functions, law.n_states, c, np.array([0.0, small]))
    if at_rest[0] != 0.0:
        raise _fail(law, f"the shear at rest must be 0 N, got {at_rest[0]:.6g} N")
    tangent = at_rest[1] / small
    if abs(tangent - stiffness) > TANGENT_TOLERANCE * stiffness:
        raise _fail(
            law,
            f"its tangent at rest is {tangent:.6g} N/m, the story stiffness is {stiffness:.6g} "
            "N/m: the linear system would describe another building",
        )


def check_rate_independent(law: StoryLaw, stiffness: float = 1.0e7) -> None:
    """One drift path run at two speeds gives the same loop (within
    :data:`RATE_TOLERANCE`), with finite shears."""
    _, slow, fast = _loops(law, stiffness)
    scale = np.max(np.abs(slow))
    if np.max(np.abs(slow - fast)) > RATE_TOLERANCE * max(scale, 1e-300):
        raise _fail(law, "one drift path at two speeds gives two loops: the law is rate-dependent")


def check_dissipates_energy(law: StoryLaw, stiffness: float = 1.0e7) -> None:
    """Over closed cycles past the yield drift (from and back to zero drift) the law
    dissipates energy (never creates it, within :data:`ENERGY_TOLERANCE`), and its shear
    stays finite and below ``k`` times the largest drift."""
    path, slow, _ = _loops(law, stiffness)
    work = np.trapezoid(slow, path)
    if work < -ENERGY_TOLERANCE * stiffness * _yield_drift(law) ** 2:
        raise _fail(law, f"over closed cycles it creates energy: {work:.6g} J")
    if np.max(np.abs(slow)) > 1.001 * stiffness * np.max(np.abs(path)):
        raise _fail(law, "its shear exceeds the initial stiffness times the largest drift")


STORY_LAW_CHECKS: tuple[Callable[..., None], ...] = (
    check_declarations,
    check_at_rest,
    check_rate_independent,
    check_dissipates_energy,
)
"""The checks of a story law, in order; each takes ``(law, stiffness=1e7)``."""


def check_story_law(law: StoryLaw, stiffness: float = 1.0e7) -> None:
    """Check a story law's contract and physics on one story of initial stiffness
    ``stiffness`` (N/m), running every check of :data:`STORY_LAW_CHECKS`:

    - its coefficients come as ``[d, n_c]`` float64 for ``d`` stories and ``state_names``
      names every state variable;
    - at rest the shear is zero and its tangent is the story stiffness (within
      :data:`TANGENT_TOLERANCE`), which the building's linear system assumes;
    - it is rate-independent: one drift path run at two speeds gives the same loop;
    - over closed cycles past the yield drift (from and back to zero drift) it dissipates
      energy (never creates it), and its shear stays finite and below ``k`` times the
      largest drift.

    Raises:
        AssertionError: a check failed (the message names the law and the check).
    """
    for check in STORY_LAW_CHECKS:
        check(law, stiffness)
