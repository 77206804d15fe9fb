"""Error metrics of the paper's §5, per output DOF, over records and time.

All functions take ``[n_records, n_steps, n_dof]`` arrays and return ``[n_dof]`` arrays.
"""

from __future__ import annotations

import numpy as np

from ..signals.errors import InputError


def _pair(prediction: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    prediction = np.asarray(prediction, dtype=np.float64)
    truth = np.asarray(truth, dtype=np.float64)
    if prediction.shape != truth.shape or prediction.ndim != 3:
        raise InputError(
            f"prediction {prediction.shape} and truth {truth.shape} must both be "
            "[n_records, n_steps, n_dof]"
        )
    return prediction, truth


def rmse(prediction: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Root-mean-square error per DOF (same unit as the inputs, m for displacements)."""
    prediction, truth = _pair(prediction, truth)
    return np.sqrt(np.mean((prediction - truth) ** 2, axis=(0, 1)))


def relative_l2(prediction: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Relative L2 error per DOF: sqrt(sum (pred - truth)^2 / sum truth^2) over records, time."""
    prediction, truth = _pair(prediction, truth)
    return np.sqrt(np.sum((prediction - truth) ** 2, axis=(0, 1)) / np.sum(truth**2, axis=(0, 1)))


def record_relative_l2(prediction: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Median over records of each record's relative L2 error, per DOF: ``sqrt(sum_t (pred
    - truth)^2 / sum_t truth^2)`` record by record; records whose truth is zero at a DOF
    are left out there (NaN where none is left). Unlike :func:`relative_l2`, which pools
    every record and is ruled by the strongest, it says how a typical record is
    predicted."""
    prediction, truth = _pair(prediction, truth)
    error = np.sum((prediction - truth) ** 2, axis=1)
    size = np.sum(truth**2, axis=1)
    ratio = np.sqrt(np.divide(error, size, out=np.full_like(error, np.nan), where=size > 0))
    return np.array(
        [np.median(c[np.isfinite(c)]) if np.isfinite(c).any() else np.nan for c in ratio.T]
    )


def largest_record_share(truth: np.ndarray) -> float:
    """The share of ``sum truth^2`` (over records, samples and DOFs of ``[n, T, dof]``) that
    its largest record holds: near ``1 / n`` when the records are alike, near 1 when one
    record rules :func:`relative_l2`."""
    truth = np.asarray(truth, dtype=np.float64)
    energy = np.sum(truth**2, axis=tuple(range(1, truth.ndim)))
    total = float(np.sum(energy))
    return float(np.max(energy)) / total if total > 0 else float("nan")


def peak_r2(prediction: np.ndarray, truth: np.ndarray, dof: int = -1) -> float:
    """Coefficient of determination of the peak absolute response of one DOF across
    records; NaN where the true peaks do not vary (one record, as a test split that
    collapses leaves): no spread to explain."""
    prediction, truth = _pair(prediction, truth)
    predicted_peak = np.max(np.abs(prediction[:, :, dof]), axis=1)
    true_peak = np.max(np.abs(truth[:, :, dof]), axis=1)
    total = np.sum((true_peak - true_peak.mean()) ** 2)
    if total == 0.0:
        return float("nan")
    return float(1.0 - np.sum((predicted_peak - true_peak) ** 2) / total)


def coverage(mean: np.ndarray, std: np.ndarray, truth: np.ndarray, k: float = 1.0) -> np.ndarray:
    """Fraction of (record, time) points per DOF where |truth - mean| <= k * std."""
    mean, truth = _pair(mean, truth)
    std = np.broadcast_to(np.asarray(std, dtype=np.float64), truth.shape)
    return np.mean(np.abs(truth - mean) <= k * std, axis=(0, 1))


def interval_coverage(lower: np.ndarray, upper: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Fraction of (record, time) points per DOF where ``lower <= truth <= upper``."""
    return np.mean(_inside(lower, upper, truth), axis=(0, 1))


def coverage_standard_error(
    lower: np.ndarray,
    upper: np.ndarray,
    truth: np.ndarray,
    calibration_records: int | None = None,
) -> np.ndarray:
    """``[dof]`` standard error of :func:`interval_coverage` over the records drawn.

    The points of one record are not independent, the records are: with
    ``calibration_records`` None this is the standard deviation ``s`` over records of each
    record's own coverage, over the square root of the ``n`` records (how far the measured
    coverage may sit from its expectation by the draw of these records alone).

    Intervals whose width is a quantile of the errors on ``calibration_records`` other
    records (split-conformal, or any refiner calibrated on a held-out split) also move
    with the draw of those: the calibrated quantile misses the true one by as much as a
    coverage measured on them would, so the standard error becomes
    ``s * sqrt(1 / n + 1 / calibration_records)``.
    """
    per_record = np.mean(_inside(lower, upper, truth), axis=1)
    spread = per_record.std(axis=0, ddof=1)
    inverse_records = 1.0 / per_record.shape[0]
    if calibration_records is not None:
        if calibration_records < 1:
            raise InputError(f"calibration_records must be positive, got {calibration_records}")
        inverse_records += 1.0 / calibration_records
    return spread * np.sqrt(inverse_records)


def _inside(lower: np.ndarray, upper: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """``[n, T, dof]`` whether ``lower <= truth <= upper`` at each point."""
    lower, truth = _pair(lower, truth)
    upper = np.broadcast_to(np.asarray(upper, dtype=np.float64), truth.shape)
    return (lower <= truth) & (truth <= upper)
