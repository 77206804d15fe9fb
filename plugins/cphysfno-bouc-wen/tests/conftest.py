"""Independent references for the Bouc-Wen building: the paper's excitation, the building's
matrices and a tight-tolerance solution of its equations, all written from the equations
and not from the plugin's code."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
import scipy.signal

MASS = 3.0e4
STIFFNESS = np.array([7.5e7, 7.0e7, 6.0e7, 4.5e7, 2.5e7])
ALPHA, EXPONENT, AMPLITUDE, YIELD = 0.1, 3.0, 1.0, 0.01
SHAPE = 1.0 / (2.0 * YIELD**EXPONENT)
DAMPING_RATIO = 0.05
COMPATIBILITY = np.eye(5) - np.eye(5, k=-1)


def paper_white_noise(n: int, seed: int, dt: float = 0.01, duration: float = 30.0):
    """``[n, T]`` records of paper Eq. (WN): S = 0.015 m^2/s^3, n = 1200, dw = pi/30."""
    rng = np.random.default_rng(seed)
    step, half = math.pi / 30.0, 600
    t = np.arange(int(round(duration / dt)) + 1) * dt
    omega = step * np.arange(1, half + 1)
    x = rng.standard_normal((n, 2 * half))
    sigma = math.sqrt(2.0 * 0.015 * step)
    return sigma * (
        x[:, :half] @ np.cos(np.outer(omega, t)) + x[:, half:] @ np.sin(np.outer(omega, t))
    )


def building_matrices(damping_ratio: float = DAMPING_RATIO):
    """Mass, elastic stiffness and classical damping matrices of the default building."""
    d = len(STIFFNESS)
    mass = MASS * np.eye(d)
    stiffness = np.zeros((d, d))
    for i in range(d):
        stiffness[i, i] += STIFFNESS[i]
        if i + 1 < d:
            stiffness[i, i] += STIFFNESS[i + 1]
            stiffness[i, i + 1] = stiffness[i + 1, i] = -STIFFNESS[i + 1]
    squares, modes = scipy.linalg.eigh(stiffness, mass)
    modal = np.diag(2.0 * damping_ratio * np.sqrt(squares))
    damping = mass @ modes @ modal @ modes.T @ mass
    return mass, stiffness, damping


def bouc_wen_rhs(t, y, a_start, a_slope, t_start, damping):
    """Right-hand side of the paper's equations for one record, state ``[u, u', h]``."""
    d = len(STIFFNESS)
    u, w, h = y[:d], y[d : 2 * d], y[2 * d :]
    drift_rate = COMPATIBILITY @ w
    shear = STIFFNESS * (ALPHA * (COMPATIBILITY @ u) + (1.0 - ALPHA) * h)
    ground = a_start + a_slope * (t - t_start)
    acceleration = -(COMPATIBILITY.T @ shear + damping @ w) / MASS - ground
    power = np.abs(h) ** (EXPONENT - 1.0)
    h_rate = (
        -SHAPE * np.abs(drift_rate) * power * h
        - SHAPE * drift_rate * power * np.abs(h)
        + AMPLITUDE * drift_rate
    )
    return np.concatenate([w, acceleration, h_rate])


def projected_rhs(basis: np.ndarray, damping: np.ndarray) -> Callable:
    """Right-hand side of the paper's equations Galerkin-projected on ``basis`` ``[5, r]``
    (mass-normalised), for one record, state ``[q, q', h]``."""
    r = basis.shape[1]
    participation = basis.T @ (MASS * np.ones(len(STIFFNESS)))

    def rhs(t, y, a_start, a_slope, t_start):
        q, q_rate, h = y[:r], y[r : 2 * r], y[2 * r :]
        u, velocity = basis @ q, basis @ q_rate
        shear = STIFFNESS * (ALPHA * (COMPATIBILITY @ u) + (1.0 - ALPHA) * h)
        ground = a_start + a_slope * (t - t_start)
        q_accel = -basis.T @ (COMPATIBILITY.T @ shear + damping @ velocity) - ground * participation
        drift_rate = COMPATIBILITY @ velocity
        power = np.abs(h) ** (EXPONENT - 1.0)
        h_rate = (
            -SHAPE * np.abs(drift_rate) * power * h
            - SHAPE * drift_rate * power * np.abs(h)
            + AMPLITUDE * drift_rate
        )
        return np.concatenate([q_rate, q_accel, h_rate])

    return rhs


def solve_piecewise(
    rhs: Callable,
    y0: np.ndarray,
    ag: np.ndarray,
    dt: float,
    rtol: float,
    atol: float,
    args: tuple = (),
) -> np.ndarray:
    """``[T, len(y0)]`` solution of ``y' = rhs(t, y, a0, slope, t0, *args)`` by DOP853, one
    sample interval at a time so that the kinks of the piecewise-linear motion fall on
    interval ends."""
    y = np.asarray(y0, dtype=np.float64)
    out = np.zeros((len(ag), len(y)))
    out[0] = y
    for i in range(len(ag) - 1):
        solution = scipy.integrate.solve_ivp(
            rhs,
            (i * dt, (i + 1) * dt),
            y,
            method="DOP853",
            rtol=rtol,
            atol=atol,
            args=(ag[i], (ag[i + 1] - ag[i]) / dt, i * dt, *args),
        )
        y = solution.y[:, -1]
        out[i + 1] = y
    return out


def elastic_response(ag: np.ndarray, dt: float, matrices) -> np.ndarray:
    """``[n, T, d]`` the exact linear response (scipy.signal.lsim, the ground acceleration
    linear between samples) of the building of ``matrices`` (mass, stiffness, damping)."""
    mass, stiffness, damping = matrices
    inverse_mass = np.linalg.inv(mass)
    d = len(mass)
    system = scipy.signal.StateSpace(
        np.block(
            [[np.zeros((d, d)), np.eye(d)], [-inverse_mass @ stiffness, -inverse_mass @ damping]]
        ),
        np.concatenate([np.zeros(d), -np.ones(d)])[:, None],
        np.hstack([np.eye(d), np.zeros((d, d))]),
        np.zeros((d, 1)),
    )
    t = np.arange(ag.shape[1]) * dt
    return np.stack([scipy.signal.lsim(system, record, t)[1] for record in ag])


def relative_l2(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per output: ``sqrt(sum (estimate - truth)^2 / sum truth^2)`` over records and time."""
    axes = tuple(range(truth.ndim - 1))
    return np.sqrt(((estimate - truth) ** 2).sum(axes) / (truth**2).sum(axes))


@pytest.fixture(scope="session")
def white_noise() -> Callable:
    return paper_white_noise


@pytest.fixture(scope="session")
def matrices() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return building_matrices()


@pytest.fixture(scope="session")
def reference_rhs() -> Callable:
    return bouc_wen_rhs


@pytest.fixture(scope="session")
def projected_reference_rhs() -> Callable:
    return projected_rhs


@pytest.fixture(scope="session")
def piecewise_solver() -> Callable:
    return solve_piecewise


@pytest.fixture(scope="session")
def rel_l2() -> Callable:
    return relative_l2
