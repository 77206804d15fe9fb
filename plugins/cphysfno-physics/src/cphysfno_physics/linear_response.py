"""Exact response of a linear structure to ground accelerations that are linear between samples.

The structure ``M u'' + C u' + K u = -M r a_g`` is written as the state space
``x' = A x + B a_g`` with ``x = [u, u']``. With ``a_g`` linear between samples (first-order
hold) and the structure at rest at ``t = 0``, the samples of the state obey exactly

    x_{k+1} = Phi x_k + Gamma0 a_k + Gamma1 a_{k+1},    x_0 = 0,

with ``Phi = exp(A dt)`` and ``Gamma0``, ``Gamma1`` read from the exponential of an augmented
matrix. Where ``A`` has a well-conditioned eigenbasis (eigenvalues ``lambda``), each
eigen-coordinate obeys the scalar recurrence ``eta_{k+1} = mu eta_k + g0 a_k + g1 a_{k+1}``
with ``mu = exp(lambda dt)``; of a conjugate pair only one member is run (the outputs take
twice its real part). A compiled kernel runs these recurrences with the records in SIMD
lanes, blocks of records spread over the cores in threads. Otherwise (a defective or
nearly defective ``A``, such as a critically damped mode or a rigid-body mode) the real
recurrence above is stepped directly.
"""

from __future__ import annotations

import numba
import numpy as np
from scipy.linalg import expm

from cphysfno_core.plugin import LinearSystem
from cphysfno_core.signals import run_in_slices

CONDITION_LIMIT = 1e6
"""Largest condition number of the (row-equilibrated) eigenvector matrix for which the
eigen-coordinate path is used; round-off grows with it, so 1e6 keeps the error near 1e-10."""

LANES = 64
"""Records advanced together by one SIMD loop of the kernel."""

WINDOW = 64
"""Samples of a block's outputs kept before they are written out, record by record."""


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
    a, b = system.state_space()
    phi, gamma0, gamma1 = first_order_hold(a, b, dt)
    eigenvalues, vectors = np.linalg.eig(a)
    output_map = np.hstack([system.output_map, np.zeros_like(system.output_map)])
    if _in_conjugate_pairs(eigenvalues) and _well_conditioned(vectors):
        return _eigen_response(eigenvalues, vectors, gamma0, gamma1, output_map, ag, dt)
    return _recurrence_response(phi, gamma0, gamma1, output_map, ag)


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


def _eigen_response(
    eigenvalues: np.ndarray,
    vectors: np.ndarray,
    gamma0: np.ndarray,
    gamma1: np.ndarray,
    output_map: np.ndarray,
    ag: np.ndarray,
    dt: float,
) -> np.ndarray:
    """Outputs from the eigen-coordinates ``eta_{k+1} = mu eta_k + g0 a_k + g1 a_{k+1}``.

    Only eigenvalues with ``Im >= 0`` are run; a member of a conjugate pair counts twice
    (the outputs are real parts).
    """
    keep = eigenvalues.imag >= 0
    inverse = np.linalg.inv(vectors)[keep]
    doubled = np.where(eigenvalues[keep].imag > 0, 2.0, 1.0)
    coefficients = np.stack([np.exp(eigenvalues[keep] * dt), inverse @ gamma0, inverse @ gamma1])
    to_output = (output_map @ vectors[:, keep]) * doubled
    recurrence = np.ascontiguousarray(np.stack([coefficients.real, coefficients.imag]))
    mapped = np.ascontiguousarray(np.stack([to_output.real, -to_output.imag]))
    n_records, n_steps = ag.shape
    out = np.empty((n_records, n_steps, output_map.shape[0]))
    run_in_slices(
        lambda rows: _modal_kernel(ag[rows], recurrence, mapped, out[rows]), n_records, LANES
    )
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath={"contract", "nsz"})
def _modal_kernel(ag, coefficients, to_output, out):
    """Write ``out [n, T, n_outputs]`` from the records ``ag [n, T]`` (m/s^2).

    ``coefficients [2, 3, M]`` holds the real and imaginary parts of ``mu``, ``g0`` and
    ``g1`` of the M eigen-coordinates run; ``to_output [2, n_outputs, M]`` the real part and
    the negated imaginary part of their map to the outputs (``y = Re(T eta)``). A block's
    outputs are kept for :data:`WINDOW` samples and then written record by record.
    """
    n_records, n_steps = ag.shape
    n_modes, n_outputs = coefficients.shape[2], to_output.shape[1]
    eta = np.empty((2, n_modes, LANES))
    block = np.empty((n_steps, LANES))
    window = np.empty((WINDOW, n_outputs, LANES))
    for first in range(0, n_records, LANES):
        count = min(LANES, n_records - first)
        block[:] = 0.0
        for lane in range(count):
            for k in range(n_steps):
                block[k, lane] = ag[first + lane, k]
        eta[:] = 0.0
        window[0] = 0.0
        for k in range(n_steps - 1):
            now, later = block[k], block[k + 1]
            for m in range(n_modes):
                mu_re, mu_im = coefficients[0, 0, m], coefficients[1, 0, m]
                g0_re, g0_im = coefficients[0, 1, m], coefficients[1, 1, m]
                g1_re, g1_im = coefficients[0, 2, m], coefficients[1, 2, m]
                real, imag = eta[0, m], eta[1, m]
                for lane in range(LANES):
                    a0, a1 = now[lane], later[lane]
                    re, im = real[lane], imag[lane]
                    real[lane] = mu_re * re - mu_im * im + g0_re * a0 + g1_re * a1
                    imag[lane] = mu_re * im + mu_im * re + g0_im * a0 + g1_im * a1
            kept = (k + 1) % WINDOW
            if kept == 0:
                _write_window(window, WINDOW, out[first : first + count, k + 1 - WINDOW :])
            for o in range(n_outputs):
                value = window[kept, o]
                value[:] = 0.0
                for m in range(n_modes):
                    c_re, c_im = to_output[0, o, m], to_output[1, o, m]
                    real, imag = eta[0, m], eta[1, m]
                    for lane in range(LANES):
                        value[lane] += c_re * real[lane] + c_im * imag[lane]
        start = (n_steps - 1) // WINDOW * WINDOW
        _write_window(window, n_steps - start, out[first : first + count, start:])


@numba.njit(inline="always", nogil=True)
def _write_window(window, length, out):
    """``out [count, >= length, n_outputs]`` from the first ``length`` samples of
    ``window [WINDOW, n_outputs, LANES]``, record by record: each record's samples are
    written in one run of consecutive memory (writing each sample of a block's records as
    it came touched ``LANES`` distant places at a time, several times slower)."""
    for lane in range(out.shape[0]):
        for kept in range(length):
            for o in range(out.shape[2]):
                out[lane, kept, o] = window[kept, o, lane]


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
