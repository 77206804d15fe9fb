"""Exact response of a linear structure to ground accelerations that are linear between samples.

The structure ``M u'' + C u' + K u = -M r a_g`` is written as the state space
``x' = A x + B a_g`` with ``x = [u, u']``. With ``a_g`` linear between samples (first-order
hold) and the structure at rest at ``t = 0``, the samples of the state obey exactly

    x_{k+1} = Phi x_k + Gamma0 a_k + Gamma1 a_{k+1},    x_0 = 0,

with ``Phi = exp(A dt)`` and ``Gamma0``, ``Gamma1`` read from the exponential of an augmented
matrix. Where ``A`` has a well-conditioned eigenbasis (eigenvalues ``lambda``), each
eigen-coordinate obeys the scalar recurrence ``eta_{k+1} = mu eta_k + g0 a_k + g1 a_{k+1}``
with ``mu = exp(lambda dt)``; a conjugate pair is run as one real second-order filter
(:func:`scipy.signal.lfilter`) over all records at once, in chunks spread over threads.
Otherwise (a defective or nearly defective ``A``, such as a critically damped mode or a
rigid-body mode) the real recurrence above is stepped directly.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm
from scipy.signal import lfilter

from cphysfno_core import LinearSystem

CONDITION_LIMIT = 1e6
"""Largest condition number of the (row-equilibrated) eigenvector matrix for which the
eigen-coordinate path is used; round-off grows with it, so 1e6 keeps the error near 1e-10."""

CHUNK_ELEMENTS = 2**20
"""Records are filtered in chunks of about this many filter samples (float64), in threads."""


def linear_response(system: LinearSystem, acceleration: np.ndarray, dt: float) -> np.ndarray:
    """Displacements ``y = L u`` of a linear structure, exact for piecewise-linear ``a_g``.

    Assumes the structure starts at rest (``u = u' = 0`` at the first sample) and that the
    ground acceleration varies linearly between consecutive samples. The result is exact
    up to round-off for any mass, damping (classical or not) and stiffness matrices with
    ``M`` invertible.

    Args:
        system: mass (kg), damping (N s/m), stiffness (N/m) ``[n_dof, n_dof]``, influence
            vector ``r [n_dof]`` and output map ``L [n_outputs, n_dof]``.
        acceleration: ``[n_records, n_steps]`` ground accelerations in m/s^2 (a 1-D array
            is one record).
        dt: time step between samples in s.

    Returns:
        ``[n_records, n_steps, n_outputs]`` output displacements in m relative to the
        ground, float64.
    """
    ag = np.atleast_2d(np.asarray(acceleration, dtype=np.float64))
    a, b = state_space(system)
    phi, gamma0, gamma1 = first_order_hold(a, b, dt)
    eigenvalues, vectors = np.linalg.eig(a)
    output_map = np.hstack([system.output_map, np.zeros_like(system.output_map)])
    if _in_conjugate_pairs(eigenvalues) and _well_conditioned(vectors):
        return _eigen_response(eigenvalues, vectors, gamma0, gamma1, output_map, ag, dt)
    return _recurrence_response(phi, gamma0, gamma1, output_map, ag)


def state_space(system: LinearSystem) -> tuple[np.ndarray, np.ndarray]:
    """``A [2 n_dof, 2 n_dof]`` and ``B = [0, -r]`` ``[2 n_dof]`` of ``x = [u (m), u' (m/s)]``."""
    n = system.n_dof
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, :n] = -np.linalg.solve(system.mass, system.stiffness)
    a[n:, n:] = -np.linalg.solve(system.mass, system.damping)
    b = np.concatenate([np.zeros(n), -system.influence])
    return a, b


def first_order_hold(
    a: np.ndarray, b: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Phi``, ``Gamma0``, ``Gamma1`` of ``x_{k+1} = Phi x_k + Gamma0 a_k + Gamma1 a_{k+1}``.

    Exact for ``x' = A x + B a_g`` with ``a_g`` linear over the step ``dt`` (s), from the
    exponential of ``[[A, B, 0], [0, 0, 1/dt], [0, 0, 0]] dt``.
    """
    n = a.shape[0]
    augmented = np.zeros((n + 2, n + 2))
    augmented[:n, :n] = a * dt
    augmented[:n, n] = b * dt
    augmented[n, n + 1] = 1.0
    exponential = expm(augmented)
    phi = exponential[:n, :n]
    start, slope = exponential[:n, n], exponential[:n, n + 1]
    return phi, start - slope, slope


def _in_conjugate_pairs(eigenvalues: np.ndarray) -> bool:
    """Whether the complex eigenvalues pair up, so only those with Im >= 0 need running."""
    return int(np.sum(eigenvalues.imag > 0)) == int(np.sum(eigenvalues.imag < 0))


def _well_conditioned(vectors: np.ndarray) -> bool:
    """Whether the eigenbasis is far from defective, whatever the units of ``u`` and ``u'``."""
    rows = vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
    return bool(np.linalg.cond(rows) <= CONDITION_LIMIT)


@dataclass(frozen=True)
class _PairFilters:
    """Real filters that produce the outputs from the eigen-coordinates, one per kept mode.

    Attributes:
        denominators: ``[n_modes, 3]`` all-pole filter ``1 / (1 + d1 z^-1 + d2 z^-1)``.
        delayed: ``[3 n_modes, n_outputs]`` weights of each filter output and its two delays.
        start_transient: ``[n_steps, n_outputs]`` output of a unit ``a_0`` that the filters
            add by starting from zero rather than from rest.
    """

    denominators: np.ndarray
    delayed: np.ndarray
    start_transient: np.ndarray


def _pair_filters(
    eigenvalues: np.ndarray,
    vectors: np.ndarray,
    gamma0: np.ndarray,
    gamma1: np.ndarray,
    output_map: np.ndarray,
    dt: float,
    n_steps: int,
) -> _PairFilters:
    """Real filters for ``eta_{k+1} = mu eta_k + g0 a_k + g1 a_{k+1}`` of each eigenvalue.

    A conjugate pair contributes twice the real part of one member ``eta``, and
    ``eta = beta(z) s`` with ``s`` the output of the real all-pole filter
    ``1 / ((1 - mu z^-1)(1 - conj(mu) z^-1))`` and ``beta(z) = (g1 + g0 z^-1)(1 - conj(mu) z^-1)``
    (a real eigenvalue has a first-order filter and ``beta(z) = g1 + g0 z^-1``), so the
    outputs are real combinations of ``s`` and its two delays. A filter started from zero
    puts ``g1 a_0 mu^k`` into ``eta``; ``start_transient`` is what that adds to the outputs.
    """
    keep = eigenvalues.imag >= 0
    paired = eigenvalues[keep].imag > 0
    inverse = np.linalg.inv(vectors)[keep]
    g0, g1 = inverse @ gamma0, inverse @ gamma1
    mu = np.exp(eigenvalues[keep] * dt)
    partner = np.where(paired, np.conj(mu), 0.0)
    to_output = (output_map @ vectors[:, keep]) * np.where(paired, 2.0, 1.0)
    beta = np.stack([g1, g0 - g1 * partner, -g0 * partner], axis=1)
    delayed = np.einsum("ij,jm->jmi", to_output, beta).real.reshape(-1, output_map.shape[0])
    denominators = np.stack([np.ones_like(mu), -(mu + partner), mu * partner], axis=1).real
    powers = mu[:, None] ** np.arange(n_steps)[None, :]
    start_transient = ((to_output * g1) @ powers).real.T
    return _PairFilters(denominators, delayed, start_transient)


def _eigen_response(
    eigenvalues: np.ndarray,
    vectors: np.ndarray,
    gamma0: np.ndarray,
    gamma1: np.ndarray,
    output_map: np.ndarray,
    ag: np.ndarray,
    dt: float,
) -> np.ndarray:
    """Outputs from the eigen-coordinates, run as real filters over chunks of records."""
    n_records, n_steps = ag.shape
    filters = _pair_filters(eigenvalues, vectors, gamma0, gamma1, output_map, dt, n_steps)
    out = np.empty((n_records, n_steps, output_map.shape[0]))
    chunk = max(1, CHUNK_ELEMENTS // (filters.delayed.shape[0] * n_steps))
    blocks = [slice(first, first + chunk) for first in range(0, n_records, chunk)]
    with ThreadPoolExecutor(max_workers=min(len(blocks), _cpu_count())) as pool:
        list(pool.map(lambda rows: _filter_block(filters, ag[rows], out[rows]), blocks))
    return out


def _filter_block(filters: _PairFilters, records: np.ndarray, out: np.ndarray) -> None:
    """Write the outputs ``[n, n_steps, n_outputs]`` of ``records [n, n_steps]`` into ``out``."""
    n, n_steps = records.shape
    taps = np.empty((n, filters.denominators.shape[0], 3, n_steps))
    for j, denominator in enumerate(filters.denominators):
        filtered = lfilter([1.0], denominator, records, axis=1)
        for delay in range(3):
            taps[:, j, delay, :delay] = 0.0
            taps[:, j, delay, delay:] = filtered[:, : n_steps - delay]
    np.matmul(taps.reshape(n, -1, n_steps).mT, filters.delayed, out=out)
    out -= records[:, :1, None] * filters.start_transient[None]


def _cpu_count() -> int:
    """CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def _recurrence_response(
    phi: np.ndarray,
    gamma0: np.ndarray,
    gamma1: np.ndarray,
    output_map: np.ndarray,
    ag: np.ndarray,
) -> np.ndarray:
    """Step the real recurrence for all records at once (used when ``A`` is near-defective)."""
    n_records, n_steps = ag.shape
    states = np.zeros((n_records, n_steps, phi.shape[0]))
    for k in range(n_steps - 1):
        states[:, k + 1] = (
            states[:, k] @ phi.T + np.outer(ag[:, k], gamma0) + np.outer(ag[:, k + 1], gamma1)
        )
    return states @ output_map.T
