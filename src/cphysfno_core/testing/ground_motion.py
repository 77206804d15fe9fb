"""The conformance checks of a ground-motion source."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..api.interfaces import GroundMotionSource
from ..signals import GroundMotions
from .helpers import fail


def check_sample_records(source: GroundMotionSource, n: int = 3) -> None:
    """``sample(n, rng)`` returns :class:`~cphysfno_core.signals.GroundMotions` of between
    1 and ``n`` records."""
    motions = source.sample(n, np.random.default_rng(123))
    if not isinstance(motions, GroundMotions):
        raise fail(source, "sample must return cphysfno_core.GroundMotions")
    if not 1 <= motions.n_records <= n:
        raise fail(source, f"sample({n}) returned {motions.n_records} records")


def check_sample_is_deterministic(source: GroundMotionSource, n: int = 3) -> None:
    """Two samples under the same seed are the same records at the same time step."""
    first = source.sample(n, np.random.default_rng(123))
    second = source.sample(n, np.random.default_rng(123))
    if not np.array_equal(first.acceleration, second.acceleration) or first.dt != second.dt:
        raise fail(source, "sample is not deterministic under the same seed")


GROUND_MOTION_CHECKS: tuple[Callable[..., None], ...] = (
    check_sample_records,
    check_sample_is_deterministic,
)
"""The checks of a ground-motion source, in order; each takes ``(source, n=3)``."""


def check_ground_motion_source(source: GroundMotionSource, n: int = 3) -> None:
    """Run every check of :data:`GROUND_MOTION_CHECKS`: ``sample`` returns GroundMotions
    of at most ``n`` finite records, deterministic under a seed."""
    for check in GROUND_MOTION_CHECKS:
        check(source, n)
