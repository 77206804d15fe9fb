"""The baselines an engineer would fit instead of a surrogate, for peak EDPs.

Both are fitted on the EDPs of the same training simulations the surrogates learn from and
scored on the same test records (:func:`~cphysfno_core.reporting.edp.log_errors`), so a
report can say when a one-line regression predicts peak drift as well as a trained model:

- :class:`CloudRegression`: the cloud analysis of performance-based earthquake engineering
  (Cornell et al. 2002, Jalayer 2003), ``ln EDP = a + b ln IM + e`` by least squares, for
  each story's PID and each floor's PFA, against Sa(T1) of the structure's first elastic
  period.
- :class:`GaussianProcess`: a Gaussian-process regression of ``ln EDP`` on the logarithms
  of a vector of intensity measures (:data:`GP_INTENSITY_MEASURES`), the kind of scalar
  surrogate SimCenter's quoFEM fits. Its mean is a linear trend in the intensity measures
  plus a zero-mean process with a squared-exponential kernel of one length scale per
  measure, and white noise; the kernel's hyperparameters maximise the marginal likelihood.

Each predicts the median ``exp(E[ln EDP])``. Training records with a value that is NaN or
not > 0 (collapsed or failed records) are left out of that EDP's fit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

from ..model.labels import ModelLabel
from ..signals import GroundMotions
from ..signals.errors import InputError
from ..signals.intensity import (
    average_spectral_acceleration,
    peak_ground_acceleration,
    peak_ground_velocity,
    significant_duration,
    spectral_acceleration,
)
from . import edp

MIN_RECORDS = 5
"""Fewest valid training records an EDP's baseline is fitted on; below, it predicts NaN."""


TREND_RECORDS_PER_TERM = 4
"""The Gaussian process's linear trend needs this many training records per term (``d + 1``
terms); on fewer its mean is a constant."""


def _spectral(factor: float) -> Callable[[GroundMotions, float], np.ndarray]:
    return lambda motions, period: spectral_acceleration(
        motions.acceleration, motions.dt, factor * period
    )


GP_INTENSITY_MEASURES: dict[str, tuple[str, Callable[[GroundMotions, float], np.ndarray]]] = {
    "PGA": ("m/s^2", lambda m, _: peak_ground_acceleration(m.acceleration)),
    "PGV": ("m/s", lambda m, _: peak_ground_velocity(m.acceleration, m.dt)),
    "Sa(T1)": ("m/s^2", _spectral(1.0)),
    "Sa(2 T1)": ("m/s^2", _spectral(2.0)),
    "Sa_avg(0.2-3 T1)": (
        "m/s^2",
        lambda m, t: average_spectral_acceleration(m.acceleration, m.dt, 0.2 * t, 3.0 * t),
    ),
    "D5-95": ("s", lambda m, _: significant_duration(m.acceleration, m.dt)),
}
"""The intensity measures of the Gaussian process, by name: (unit, function of the motions
and the first elastic period T1 in s giving ``[n]`` values). Spectral ordinates are 5 %
damped pseudo-accelerations."""


def intensity_vector(motions: GroundMotions, first_period: float) -> np.ndarray:
    """``[n, 6]`` the measures of :data:`GP_INTENSITY_MEASURES` of every record, in order."""
    return np.column_stack([f(motions, first_period) for _, f in GP_INTENSITY_MEASURES.values()])


def sa_t1(motions: GroundMotions, first_period: float) -> np.ndarray:
    """``[n]`` Sa(T1), 5 % damped, in m/s^2: the cloud regression's intensity measure."""
    return _spectral(1.0)(motions, first_period)


def _log(values: np.ndarray) -> np.ndarray:
    """``ln`` where > 0 and finite, NaN elsewhere."""
    values = np.asarray(values, dtype=np.float64)
    found = np.full(values.shape, np.nan)
    valid = np.isfinite(values) & (values > 0)
    found[valid] = np.log(values[valid])
    return found


def _features(im: np.ndarray) -> np.ndarray:
    """``[n, d]`` log intensity measures from ``[n]`` or ``[n, d]`` values."""
    im = np.asarray(im, dtype=np.float64)
    return _log(im[:, None] if im.ndim == 1 else im)


def _targets(values: np.ndarray, n: int) -> np.ndarray:
    values = np.asarray(values, dtype=np.float64)
    if values.ndim != 2 or values.shape[0] != n:
        raise InputError(f"EDPs must be [n_records = {n}, n_edps], got {values.shape}")
    return _log(values)


class _PerColumn:
    """A regression of each column of ``ln EDP`` on log intensity measures, fitted on the
    records where both are known; subclasses fit one column (:meth:`_fit_column`) and
    predict it (:meth:`_predict_column`)."""

    def fit(self, im: np.ndarray, values: np.ndarray):
        """Fit on ``im`` (``[n]`` one measure, or ``[n, d]``, each > 0) and ``values``
        ``[n, k]`` (each EDP column > 0; NaN or non-positive entries are left out).

        Returns:
            self.
        """
        x = _features(im)
        y = _targets(values, x.shape[0])
        self.n_features_ = x.shape[1]
        self.columns_ = []
        for j in range(y.shape[1]):
            rows = np.isfinite(y[:, j]) & np.all(np.isfinite(x), axis=1)
            fitted = self._fit_column(x[rows], y[rows, j]) if rows.sum() >= MIN_RECORDS else None
            self.columns_.append(fitted)
        return self

    def predict(self, im: np.ndarray) -> np.ndarray:
        """``[n, k]`` median EDPs ``exp(E[ln EDP])`` at ``im`` (NaN for records with a
        measure that is not > 0 and for EDPs fitted on fewer than :data:`MIN_RECORDS`)."""
        if not hasattr(self, "columns_"):
            raise InputError(f"{type(self).__name__} is not fitted: call fit first")
        x = _features(im)
        if x.shape[1] != self.n_features_:
            raise InputError(f"fitted on {self.n_features_} measures, given {x.shape[1]}")
        known = np.all(np.isfinite(x), axis=1)
        found = np.full((x.shape[0], len(self.columns_)), np.nan)
        for j, fitted in enumerate(self.columns_):
            if fitted is not None and known.any():
                found[known, j] = np.exp(self._predict_column(fitted, x[known]))
        return found

    def _fit_column(self, x: np.ndarray, y: np.ndarray):
        raise NotImplementedError

    def _predict_column(self, fitted, x: np.ndarray) -> np.ndarray:
        raise NotImplementedError


@dataclass(frozen=True)
class CloudFit:
    """``ln EDP = intercept + slope ln IM`` with residual standard deviation ``beta``
    (least squares, ``n - 2`` degrees of freedom)."""

    intercept: float
    slope: float
    beta: float


class CloudRegression(_PerColumn):
    """``ln EDP = a + b ln IM`` by least squares for each EDP column; after :meth:`fit`,
    ``columns_`` holds each column's :class:`CloudFit` (None where too few records)."""

    def _fit_column(self, x: np.ndarray, y: np.ndarray) -> CloudFit:
        design = np.column_stack([np.ones(len(y)), x[:, 0]])
        (a, b), *_ = np.linalg.lstsq(design, y, rcond=None)
        residual = y - design @ np.array([a, b])
        beta = float(np.sqrt(residual @ residual / max(len(y) - 2, 1)))
        return CloudFit(float(a), float(b), beta)

    def _predict_column(self, fitted: CloudFit, x: np.ndarray) -> np.ndarray:
        return fitted.intercept + fitted.slope * x[:, 0]


@dataclass(frozen=True)
class _GPColumn:
    """One column's Gaussian process on standardised inputs."""

    shift: np.ndarray
    scale: np.ndarray
    trend: np.ndarray
    x: np.ndarray
    alpha: np.ndarray
    signal: float
    lengths: np.ndarray
    noise: float


class GaussianProcess(_PerColumn):
    """Gaussian-process regression of ``ln EDP`` on ``d`` log intensity measures, each EDP
    column on its own.

    On inputs standardised over the training records, ``ln EDP = [1, x] w + f(x) + e``:
    ``w`` by least squares (a constant alone on fewer than :data:`TREND_RECORDS_PER_TERM`
    records per term), ``f`` a zero-mean process with covariance ``s^2 exp(-sum_d
    (x_d - x'_d)^2 / (2 l_d^2))`` and ``e`` white noise of variance ``n^2``; ``s``, ``l_d``
    and ``n`` maximise the log marginal likelihood of the trend's residuals (L-BFGS-B with
    the analytic gradient, from unit length scales). The prediction is the trend plus the
    posterior mean of ``f``.
    """

    def _fit_column(self, x: np.ndarray, y: np.ndarray) -> _GPColumn:
        shift = x.mean(axis=0)
        scale = x.std(axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        xs = (x - shift) / scale
        design = _design(xs, len(y))
        trend, *_ = np.linalg.lstsq(design, y, rcond=None)
        residual = y - design @ trend
        spread = max(float(np.std(residual)), 1e-6)
        target = residual / spread
        squared = (xs[:, None, :] - xs[None, :, :]) ** 2
        d = xs.shape[1]
        start = np.concatenate([[0.0], np.zeros(d), [np.log(0.5)]])
        bounds = [(-5.0, 3.0)] + [(-3.0, 5.0)] * d + [(-6.0, 1.0)]
        result = scipy.optimize.minimize(
            _negative_log_likelihood,
            start,
            args=(squared, target),
            jac=True,
            method="L-BFGS-B",
            bounds=bounds,
        )
        theta = result.x
        signal, lengths, noise = np.exp(theta[0]), np.exp(theta[1:-1]), np.exp(theta[-1])
        cov = _covariance(squared, signal, lengths) + noise**2 * np.eye(len(y))
        alpha = scipy.linalg.cho_solve(scipy.linalg.cho_factor(cov, lower=True), target)
        return _GPColumn(
            shift, scale, trend, xs, alpha * spread, float(signal), lengths, float(noise)
        )

    def _predict_column(self, fitted: _GPColumn, x: np.ndarray) -> np.ndarray:
        xs = (x - fitted.shift) / fitted.scale
        design = _design(xs, len(fitted.x))
        squared = (xs[:, None, :] - fitted.x[None, :, :]) ** 2
        cross = _covariance(squared, fitted.signal, fitted.lengths)
        return design @ fitted.trend + cross @ fitted.alpha


def _design(xs: np.ndarray, n_fitted: int) -> np.ndarray:
    """The trend's regressors: ``[1, x]``, or ``[1]`` alone when fewer than
    :data:`TREND_RECORDS_PER_TERM` records per term were fitted on."""
    ones = np.ones((len(xs), 1))
    if n_fitted < TREND_RECORDS_PER_TERM * (xs.shape[1] + 1):
        return ones
    return np.column_stack([ones, xs])


def _covariance(squared: np.ndarray, signal: float, lengths: np.ndarray) -> np.ndarray:
    """``s^2 exp(-sum_d D_d / (2 l_d^2))`` from the squared differences ``D [.., .., d]``."""
    return signal**2 * np.exp(-0.5 * np.sum(squared / lengths**2, axis=-1))


def _negative_log_likelihood(
    theta: np.ndarray, squared: np.ndarray, y: np.ndarray
) -> tuple[float, np.ndarray]:
    """Negative log marginal likelihood of ``y`` and its gradient in ``theta = [ln s,
    ln l_1 .. ln l_d, ln n]``: ``d/dtheta_j = -tr((a a^T - K^-1) dK/dtheta_j) / 2``."""
    signal, lengths, noise = np.exp(theta[0]), np.exp(theta[1:-1]), np.exp(theta[-1])
    kernel = _covariance(squared, signal, lengths)
    cov = kernel + (noise**2 + 1e-10) * np.eye(len(y))
    try:
        factor = scipy.linalg.cho_factor(cov, lower=True)
    except np.linalg.LinAlgError:
        return 1e25, np.zeros_like(theta)
    alpha = scipy.linalg.cho_solve(factor, y)
    inverse = scipy.linalg.cho_solve(factor, np.eye(len(y)))
    value = 0.5 * y @ alpha + np.sum(np.log(np.diag(factor[0]))) + 0.5 * len(y) * np.log(2 * np.pi)
    inner = np.outer(alpha, alpha) - inverse
    grad = np.empty_like(theta)
    grad[0] = -0.5 * np.sum(inner * 2.0 * kernel)
    for k, length in enumerate(lengths):
        grad[1 + k] = -0.5 * np.sum(inner * kernel * squared[:, :, k] / length**2)
    grad[-1] = -0.5 * np.trace(inner) * 2.0 * noise**2
    return float(value), grad


BASELINES = {
    "baseline-cloud": "cloud regression ln EDP = a + b ln Sa(T1)",
    "baseline-gp": "Gaussian process on ln " + ", ".join(GP_INTENSITY_MEASURES),
}
"""The baselines' labels in ``metrics.json`` and the report, with what each is."""


def fit_and_predict(
    train: edp.EDPs,
    train_motions: GroundMotions,
    targets: dict[str, GroundMotions],
    first_period: float,
) -> dict[str, dict[str, edp.EDPs]]:
    """Both baselines fitted on the training records' scored EDPs (PID per story, PFA and
    PFV per floor above the ground, PD per output, PR per named response the structure
    records: :func:`~cphysfno_core.edp.scored_names`), predicting the records of each
    motion set in ``targets``.

    Returns:
        ``{label: {target name: EDPs}}`` for each label of :data:`BASELINES`; the predicted
        EDPs have the ground's column of the motions themselves (PGA, PGV) and no RID (a
        peak-EDP regression says nothing of it).
    """
    keys = edp.scored_names(train)
    starts = [edp.EDP_TABLE[key].first_location for key in keys]
    tables = [train.values[k][:, a:] for k, a in zip(keys, starts, strict=True)]
    values = np.column_stack(tables)
    bounds = np.cumsum([0, *(t.shape[1] for t in tables)])
    found: dict[str, dict[str, edp.EDPs]] = {}
    for label, model, measure in (
        ("baseline-cloud", CloudRegression(), sa_t1),
        ("baseline-gp", GaussianProcess(), intensity_vector),
    ):
        model.fit(measure(train_motions, first_period), values)
        found[label] = {}
        for name, motions in targets.items():
            predicted = model.predict(measure(motions, first_period))
            ground = {
                "PFA": peak_ground_acceleration(motions.acceleration),
                "PFV": peak_ground_velocity(motions.acceleration, motions.dt),
            }
            tables = {}
            for i, (key, start) in enumerate(zip(keys, starts, strict=True)):
                table = predicted[:, bounds[i] : bounds[i + 1]]
                tables[key] = np.column_stack([ground[key], table]) if start else table
            found[label][name] = train.with_values(tables)
    return found


def beaten_surrogates(
    models: dict[str, dict], baseline_rows: dict[str, dict], names: dict[str, list[str]]
) -> list[dict]:
    """Where a baseline beats every surrogate: for each scored EDP (``"PID"`` per story,
    ``"PFA"`` per floor, ...) and location whose best baseline has a lower median test
    error than every trained model (rows of ``models`` not labelled ``physics-*``).

    Args:
        models: the ``models`` rows of ``metrics.json`` (with their ``edp`` errors).
        baseline_rows: the ``baselines`` rows.
        names: the columns each EDP is scored at (``EDPScorer.locations``).

    Returns:
        One ``{"edp", "location", "baseline", "baseline_error", "surrogate",
        "surrogate_error"}`` per such place (median ``|ln(predicted / simulated)|``).
    """
    surrogates = {
        label: row["edp"]
        for label, row in models.items()
        if "edp" in row and ModelLabel.parse(label).is_trained
    }
    found = []
    if not surrogates or not baseline_rows:
        return found
    for key, locations in names.items():
        scoring = {k: v[key] for k, v in surrogates.items() if key in v}
        if not scoring:  # no surrogate predicts it (a named response's peak)
            continue
        for j, location in enumerate(locations):
            surrogate, ours = _best({k: v["median"][j] for k, v in scoring.items()})
            baseline, theirs = _best(
                {k: v["edp"][key]["median"][j] for k, v in baseline_rows.items()}
            )
            if baseline is not None and (surrogate is None or theirs < ours):
                found.append(
                    {
                        "edp": key,
                        "location": location,
                        "baseline": baseline,
                        "baseline_error": theirs,
                        "surrogate": surrogate,
                        "surrogate_error": ours,
                    }
                )
    return found


def _best(errors: dict[str, float]) -> tuple[str | None, float]:
    """The label with the least finite error, and that error (None, NaN if none)."""
    finite = {k: v for k, v in errors.items() if np.isfinite(v)}
    if not finite:
        return None, float("nan")
    label = min(finite, key=finite.get)
    return label, float(finite[label])


def describe_beaten(found: list[dict]) -> list[str]:
    """One sentence per EDP of :func:`beaten_surrogates`."""
    lines = []
    for key in dict.fromkeys(item["edp"] for item in found):
        places = [
            f"{item['location']} ({item['baseline']} {item['baseline_error']:.3f} against "
            f"{item['surrogate']} {item['surrogate_error']:.3f})"
            for item in found
            if item["edp"] == key
        ]
        lines.append(
            f"a baseline predicts {key} better than every trained model at "
            + ", ".join(places)
            + " (median |ln(predicted / simulated)| on the test records)"
        )
    return lines
