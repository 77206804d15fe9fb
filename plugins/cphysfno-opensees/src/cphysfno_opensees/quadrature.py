"""Gauss-Lobatto integration along a force-based element, shared by both structures."""

from __future__ import annotations

import numpy as np


def lobatto(points: int) -> tuple[np.ndarray, np.ndarray]:
    """``[points]`` Gauss-Lobatto locations ``xi`` in [0, 1], both ends included, and
    their weights (summing to 1), as OpenSees' ``Lobatto`` beam integration places them.

    Raises:
        ValueError: fewer than 3 points.
    """
    if points < 3:
        raise ValueError("Gauss-Lobatto integration needs at least 3 points")
    inner = np.polynomial.legendre.Legendre.basis(points - 1).deriv().roots()
    nodes = np.concatenate([[-1.0], np.sort(inner.real), [1.0]])
    legendre = np.polynomial.legendre.Legendre.basis(points - 1)(nodes)
    weights = 2.0 / (points * (points - 1) * legendre**2)
    return 0.5 * (nodes + 1.0), 0.5 * weights
