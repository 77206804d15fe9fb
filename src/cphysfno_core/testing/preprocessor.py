"""The conformance checks of a physics preprocessor on a structure it works on.

The checks of one preprocessor on one structure share one fitted copy of it: some fits
(a stick calibrated by pushovers) take seconds, and each check would repeat them.
"""

from __future__ import annotations

import copy
import weakref
from collections.abc import Callable

import numpy as np

from ..api.interfaces import PhysicsPreprocessor, Structure
from ..signals import GroundMotions
from ..signals.errors import NotFittedError
from .helpers import check_array, expect, fail, small_motions

_FITTED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""preprocessor -> structure -> (a fitted copy, what its ``fit`` returned)."""


def _fitted(
    preprocessor: PhysicsPreprocessor, structure: Structure
) -> tuple[PhysicsPreprocessor, PhysicsPreprocessor]:
    """A copy of ``preprocessor`` fitted on ``structure`` (fitted once per pair) and what
    its ``fit`` returned."""
    on = _FITTED.setdefault(preprocessor, weakref.WeakKeyDictionary())
    if structure not in on:
        fresh = copy.deepcopy(preprocessor)
        on[structure] = (fresh, fresh.fit(structure))
    return on[structure]


def check_not_usable_before_fit(preprocessor: PhysicsPreprocessor, structure: Structure) -> None:
    """``transform`` before ``fit`` raises :class:`~cphysfno_core.NotFittedError`."""
    fresh = copy.deepcopy(preprocessor)
    expect(preprocessor, NotFittedError, fresh.transform, small_motions())


def check_fit_returns_itself(preprocessor: PhysicsPreprocessor, structure: Structure) -> None:
    """``fit(structure)`` returns the preprocessor itself."""
    fresh, returned = _fitted(preprocessor, structure)
    if returned is not fresh:
        raise fail(preprocessor, "fit must return the preprocessor itself")


def check_z_shape(preprocessor: PhysicsPreprocessor, structure: Structure) -> None:
    """``transform`` gives z ``[n, T, n_outputs]``, finite float64 (m), on the motions'
    own grid at any T."""
    fitted = _fitted(preprocessor, structure)[0]
    for n_steps in (201, 334):
        motions = small_motions(n_steps=n_steps)
        shape = (motions.n_records, n_steps, structure.n_outputs)
        check_array(preprocessor, fitted.transform(motions), shape, "z")


def check_transform_is_deterministic(
    preprocessor: PhysicsPreprocessor, structure: Structure
) -> None:
    """Two transforms of the same motions give the same z."""
    fitted = _fitted(preprocessor, structure)[0]
    motions = small_motions(n_steps=101)
    if not np.array_equal(fitted.transform(motions), fitted.transform(motions)):
        raise fail(preprocessor, "transform is not deterministic")


def check_zero_motion_gives_zero_z(preprocessor: PhysicsPreprocessor, structure: Structure) -> None:
    """Zero ground motion gives zero z."""
    rest = _fitted(preprocessor, structure)[0].transform(GroundMotions(np.zeros((1, 101)), 0.01))
    if np.max(np.abs(rest)) != 0.0:
        raise fail(preprocessor, "zero ground motion must give zero z")


PREPROCESSOR_CHECKS: tuple[Callable[[PhysicsPreprocessor, Structure], None], ...] = (
    check_not_usable_before_fit,
    check_fit_returns_itself,
    check_z_shape,
    check_transform_is_deterministic,
    check_zero_motion_gives_zero_z,
)
"""The checks of a preprocessor, in order; each takes ``(preprocessor, structure)``."""


def check_preprocessor(preprocessor: PhysicsPreprocessor, structure: Structure) -> None:
    """Run every check of :data:`PREPROCESSOR_CHECKS`: not usable before ``fit``; ``z`` of
    shape ``[n, T, n_outputs]`` in float64 on the motion's own grid at any T; zero motion
    gives zero z; deterministic.

    Raises:
        CapabilityError: ``structure`` lacks a capability the preprocessor requires (from
            its ``fit``).
    """
    for check in PREPROCESSOR_CHECKS:
        check(preprocessor, structure)
