"""The conformance checks of a refiner, on a small synthetic problem: ``z``, the operator's
output ``u_hat`` near it and the truth ``u`` between them, each ``[6, 80, 2]``."""

from __future__ import annotations

import copy
from collections.abc import Callable

import numpy as np

from ..api.interfaces import Refiner
from ..signals.errors import NotFittedError
from .helpers import check_array, expect, fail


def _problem() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(z, u_hat, u)``, the same on every call."""
    rng = np.random.default_rng(0)
    z = rng.standard_normal((6, 80, 2))
    u_hat = z + 0.1 * rng.standard_normal(z.shape)
    u = 0.5 * z + 0.5 * u_hat + 0.05 * rng.standard_normal(z.shape)
    return z, u_hat, u


def _fitted(refiner: Refiner) -> tuple[Refiner, Refiner]:
    """A copy of ``refiner`` and what its ``fit`` on :func:`_problem` returned."""
    z, u_hat, u = _problem()
    fresh = copy.deepcopy(refiner)
    return fresh, fresh.fit(z, u_hat, u, np.random.default_rng(1))


def check_not_usable_before_fit(refiner: Refiner) -> None:
    """``predict`` before ``fit`` raises :class:`~cphysfno_core.NotFittedError`."""
    z, u_hat, _ = _problem()
    expect(refiner, NotFittedError, copy.deepcopy(refiner).predict, z, u_hat)


def check_fit_returns_itself(refiner: Refiner) -> None:
    """``fit`` returns the refiner itself."""
    fresh, returned = _fitted(refiner)
    if returned is not fresh:
        raise fail(refiner, "fit must return the refiner itself")


def check_prediction(refiner: Refiner) -> None:
    """``predict`` gives ``(mean, std)`` of the input's shape, finite float64, std >= 0."""
    z, u_hat, _ = _problem()
    mean, std = _fitted(refiner)[0].predict(z, u_hat)
    for what, values in (("mean", mean), ("std", std)):
        check_array(refiner, values, z.shape, what)
    if (np.asarray(std) < 0).any():
        raise fail(refiner, "std must be >= 0")


def check_state_dict_round_trip(refiner: Refiner) -> None:
    """A fresh instance loaded with a fitted one's ``state_dict`` predicts the same."""
    z, u_hat, _ = _problem()
    fitted = _fitted(refiner)[0]
    twin = copy.deepcopy(refiner)
    twin.load_state_dict(fitted.state_dict())
    if not np.array_equal(twin.predict(z, u_hat)[0], fitted.predict(z, u_hat)[0]):
        raise fail(refiner, "a state_dict round trip changes the prediction")


def check_fit_is_deterministic(refiner: Refiner) -> None:
    """Two fits under the same rng predict the same."""
    z, u_hat, _ = _problem()
    first, second = _fitted(refiner)[0], _fitted(refiner)[0]
    if not np.array_equal(first.predict(z, u_hat)[0], second.predict(z, u_hat)[0]):
        raise fail(refiner, "fit is not deterministic under the same rng")


REFINER_CHECKS: tuple[Callable[[Refiner], None], ...] = (
    check_not_usable_before_fit,
    check_fit_returns_itself,
    check_prediction,
    check_state_dict_round_trip,
    check_fit_is_deterministic,
)
"""The checks of a refiner, in order."""


def check_refiner(refiner: Refiner) -> None:
    """Run every check of :data:`REFINER_CHECKS`: not usable before ``fit``; ``(mean,
    std)`` of the input shape with std >= 0; a state-dict round trip into a fresh instance
    reproduces the prediction; deterministic under the same rng."""
    for check in REFINER_CHECKS:
        check(refiner)
