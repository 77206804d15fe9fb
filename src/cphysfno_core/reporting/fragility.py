"""Lognormal fragility curves fitted by maximum likelihood, with bootstrap intervals and
collapse combined by total probability.

A fragility is the probability that a demand exceeds a limit state given the intensity
measure ``x`` of the motion: ``P(x) = Phi(ln(x / median) / beta)``. Each record gives one
``(x_i, exceeded_i)``; the fit maximises the binomial likelihood
``sum_i y_i ln P(x_i) + (1 - y_i) ln(1 - P(x_i))`` (Baker 2015, "Efficient analytical
fragility function fitting using dynamic structural analysis", Earthquake Spectra 31(1)),
which needs no binning of the records into intensity levels.

With collapses, the probability of exceeding a limit state is
``P(C | x) + (1 - P(C | x)) P(exceed | x, no collapse)`` (total probability), each part
fitted on its own records.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import scipy.optimize
import scipy.stats

from ..signals.errors import InputError

BETA_FLOOR = 1e-3
"""Smallest dispersion a fit returns: records that separate perfectly at one intensity
would drive the maximum-likelihood beta to zero."""

BETA_CEILING = 3.0
"""Largest dispersion a fit returns: records whose exceedance does not depend on the
intensity (a narrow range of intensities, or demands that do not follow it) would drive
beta and the median without bound."""

MEDIAN_RANGE = 3.0
"""A fitted median stays within ``exp(3)`` (about 20) times the records' range of
intensities."""


@dataclass(frozen=True)
class Fragility:
    """A lognormal fragility curve.

    Attributes:
        median: intensity at which the probability of exceedance is 0.5, in the intensity
            measure's unit.
        beta: logarithmic standard deviation (dispersion).
    """

    median: float
    beta: float

    def probability(self, intensity: np.ndarray | float) -> np.ndarray:
        """Probability of exceedance at ``intensity`` (same shape)."""
        x = np.asarray(intensity, dtype=np.float64)
        return scipy.stats.norm.cdf(np.log(np.maximum(x, 1e-300) / self.median) / self.beta)


@dataclass(frozen=True)
class FragilityFit:
    """A fitted fragility with its bootstrap intervals and the data behind it.

    Attributes:
        fragility: the maximum-likelihood curve.
        median_interval: ``(low, high)`` bootstrap percentile interval of the median.
        beta_interval: ``(low, high)`` bootstrap percentile interval of beta.
        n_records: records in the fit.
        n_exceeded: of which exceeded the limit state.
        flags: why the records may not determine the curve (:func:`fit_flags`); empty for
            a fit they support.
    """

    fragility: Fragility
    median_interval: tuple[float, float]
    beta_interval: tuple[float, float]
    n_records: int
    n_exceeded: int
    flags: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """JSON-ready: ``median``, ``beta``, their intervals and the counts."""
        return {
            **asdict(self.fragility),
            "median_interval": list(self.median_interval),
            "beta_interval": list(self.beta_interval),
            "n_records": self.n_records,
            "n_exceeded": self.n_exceeded,
            "flags": list(self.flags),
        }


MIN_OUTCOMES = 5
"""Fewest records on each side of a limit state (exceeding it, and not) for a fit that
:func:`fit_flags` does not flag."""


def fit_flags(
    fragility: Fragility, intensity: np.ndarray, exceeded: np.ndarray
) -> tuple[str, ...]:
    """Why the records ``(intensity [n], exceeded [n])`` may not determine ``fragility``:
    beta at :data:`BETA_FLOOR` or :data:`BETA_CEILING` (the records separate perfectly, or
    do not follow the intensity), fewer than :data:`MIN_OUTCOMES` records exceeding the
    limit state or fewer not exceeding it, a median outside the records' intensities (an
    extrapolation)."""
    x = np.asarray(intensity, dtype=np.float64)
    y = np.asarray(exceeded, dtype=bool)
    flags = []
    if fragility.beta <= BETA_FLOOR * 1.01 or fragility.beta >= BETA_CEILING * 0.99:
        flags.append(f"beta {fragility.beta:.3g} at its bound")
    if y.sum() < MIN_OUTCOMES:
        flags.append(f"only {int(y.sum())} of {y.size} records exceed it")
    if (~y).sum() < MIN_OUTCOMES:
        flags.append(f"only {int((~y).sum())} of {y.size} records stay below it")
    if not x.min() <= fragility.median <= x.max():
        flags.append(
            f"median {fragility.median:.4g} outside the records' intensities "
            f"({x.min():.4g}-{x.max():.4g})"
        )
    return tuple(flags)


def _check(intensity: np.ndarray, exceeded: np.ndarray, what: str) -> tuple[np.ndarray, ...]:
    x = np.asarray(intensity, dtype=np.float64).ravel()
    y = np.asarray(exceeded, dtype=bool).ravel()
    if x.shape != y.shape or x.size == 0:
        raise InputError(
            f"{what}: intensity and exceedance need one value per record, got {x.size} and {y.size}"
        )
    if not (np.all(np.isfinite(x)) and np.all(x > 0)):
        raise InputError(f"{what}: intensity measures must be finite and > 0")
    if not y.any():
        raise InputError(
            f"{what}: no record exceeds it (largest intensity {x.max():.4g}): lower the limit "
            "state or use stronger motions"
        )
    if y.all():
        raise InputError(
            f"{what}: every record exceeds it (smallest intensity {x.min():.4g}): raise the "
            "limit state or use weaker motions"
        )
    return x, y


def fit_lognormal(
    intensity: np.ndarray, exceeded: np.ndarray, what: str = "limit state"
) -> Fragility:
    """The maximum-likelihood lognormal fragility of records with intensities ``intensity``
    ``[n]`` (> 0) that did (True) or did not exceed a limit state, ``exceeded [n]``.
    beta is kept within :data:`BETA_FLOOR` - :data:`BETA_CEILING` and the median within
    :data:`MEDIAN_RANGE` of the intensities: a fit at a bound says the records do not
    determine the curve.

    Raises:
        InputError: the arrays differ in length, an intensity is not positive, or no record
            (or every record) exceeded: the fit would be meaningless (the message names
            ``what``).
    """
    x, y = _check(intensity, exceeded, what)
    log_x = np.log(x)

    def negative_log_likelihood(theta: np.ndarray) -> float:
        z = (log_x - theta[0]) / np.exp(theta[1])
        return -(scipy.stats.norm.logcdf(z[y]).sum() + scipy.stats.norm.logcdf(-z[~y]).sum())

    bounds = [
        (log_x.min() - MEDIAN_RANGE, log_x.max() + MEDIAN_RANGE),
        (np.log(BETA_FLOOR), np.log(BETA_CEILING)),
    ]
    start = np.array([0.5 * (log_x[y].mean() + log_x[~y].mean()), np.log(0.4)])
    best = scipy.optimize.minimize(
        negative_log_likelihood,
        start,
        method="L-BFGS-B",
        bounds=bounds,
        options={"ftol": 1e-15, "gtol": 1e-10, "maxiter": 4000},
    )
    return Fragility(float(np.exp(best.x[0])), float(np.exp(best.x[1])))


def fit_with_intervals(
    intensity: np.ndarray,
    exceeded: np.ndarray,
    rng: np.random.Generator,
    n_bootstrap: int = 200,
    level: float = 0.9,
    what: str = "limit state",
) -> FragilityFit:
    """:func:`fit_lognormal` with percentile bootstrap intervals (records resampled with
    replacement ``n_bootstrap`` times; resamples where no record, or every record,
    exceeded are drawn again)."""
    x, y = _check(intensity, exceeded, what)
    fragility = fit_lognormal(x, y, what)
    medians, betas = [], []
    while len(medians) < n_bootstrap:
        pick = rng.integers(0, x.size, x.size)
        if y[pick].all() or not y[pick].any():
            continue
        again = fit_lognormal(x[pick], y[pick], what)
        medians.append(again.median)
        betas.append(again.beta)
    tails = 100.0 * np.array([(1.0 - level) / 2.0, (1.0 + level) / 2.0])
    return FragilityFit(
        fragility,
        tuple(float(v) for v in np.percentile(medians, tails)),
        tuple(float(v) for v in np.percentile(betas, tails)),
        int(x.size),
        int(y.sum()),
        fit_flags(fragility, x, y),
    )


def with_collapse(
    demand: Fragility, collapse: Fragility | None, intensity: np.ndarray
) -> np.ndarray:
    """Probability of exceeding a limit state at ``intensity``, collapse counted:
    ``P(C | x) + (1 - P(C | x)) P(exceed | x, no collapse)``; without a collapse fragility,
    the demand fragility alone."""
    p = demand.probability(intensity)
    if collapse is None:
        return p
    p_collapse = collapse.probability(intensity)
    return p_collapse + (1.0 - p_collapse) * p


def lognormal_through(probability: np.ndarray, intensity: np.ndarray) -> Fragility:
    """The lognormal fragility closest (least squares in probability) to a curve given at
    ``intensity`` ``[m]`` (increasing, > 0): a summary of a combined curve."""
    x = np.asarray(intensity, dtype=np.float64)
    p = np.asarray(probability, dtype=np.float64)

    def misfit(theta: np.ndarray) -> float:
        curve = scipy.stats.norm.cdf((np.log(x) - theta[0]) / np.exp(theta[1]))
        return float(np.sum((curve - p) ** 2))

    middle = np.log(x[np.argmin(np.abs(p - 0.5))])
    best = scipy.optimize.minimize(
        misfit,
        np.array([middle, np.log(0.4)]),
        method="Nelder-Mead",
        options={"xatol": 1e-9, "fatol": 1e-14, "maxiter": 4000},
    )
    return Fragility(float(np.exp(best.x[0])), float(max(np.exp(best.x[1]), BETA_FLOOR)))
