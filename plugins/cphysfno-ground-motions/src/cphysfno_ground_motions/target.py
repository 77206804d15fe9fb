"""Target spectra: median and log-standard deviation of 5%-damped pseudo-spectral
acceleration from the NGA-West2 BSSA14 model (Boore, Stewart, Seyhan and Atkinson 2014) for
one scenario, with ordinates correlated across periods by Baker and Jayaram (2008).

Both models come from the ``pygmm`` package, imported when a target is first built (it
loads pandas and matplotlib, which the rest of this package does not need).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from cphysfno_core import InputError
from cphysfno_core.signals.intensity import STANDARD_GRAVITY, SpectrumBand
from scipy.stats import norm


@dataclass(frozen=True)
class TargetSpectrum:
    """A lognormal response-spectrum model with correlated ordinates.

    Attributes:
        periods: ``[P]`` periods in s, increasing.
        median: ``[P]`` median pseudo-spectral acceleration in m/s^2.
        ln_std: ``[P]`` standard deviation of ln PSA.
        correlation: ``[P, P]`` correlation of ln PSA between periods.
        damping: damping ratio the spectra are defined for.
    """

    periods: np.ndarray
    median: np.ndarray
    ln_std: np.ndarray
    correlation: np.ndarray
    damping: float = 0.05

    def quantile(self, probability: float) -> np.ndarray:
        """``[P]`` PSA in m/s^2 not exceeded with ``probability`` at each period."""
        return self.median * np.exp(norm.ppf(probability) * self.ln_std)

    def band(self, low: float = 0.025, high: float = 0.975) -> SpectrumBand:
        """The median and the ``low``-``high`` quantile band, for figures and reports."""
        return SpectrumBand(
            self.periods,
            self.median,
            self.quantile(low),
            self.quantile(high),
            self.damping,
            f"{low:.1%} and {high:.1%}",
        )

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """``[n, P]`` spectra in m/s^2 drawn from the joint lognormal distribution.

        The standard normal draws are ``[n, P]`` from ``rng``, mapped through the
        eigen-decomposition of the correlation matrix (clipped to be positive semidefinite).
        """
        values, vectors = np.linalg.eigh(self.correlation)
        root = vectors * np.sqrt(np.clip(values, 0.0, None))
        epsilon = rng.standard_normal((int(n), self.periods.size)) @ root.T
        return self.median * np.exp(epsilon * self.ln_std)


def bssa14_target(
    magnitude: float,
    rjb_km: float,
    vs30: float,
    mechanism: str,
    region: str,
    periods: np.ndarray,
) -> TargetSpectrum:
    """BSSA14 median and sigma for a scenario, with the Baker-Jayaram (2008) correlation.

    Args:
        magnitude: moment magnitude M.
        rjb_km: Joyner-Boore distance in km.
        vs30: time-averaged shear-wave velocity of the top 30 m in m/s.
        mechanism: ``"U"`` (unspecified), ``"SS"``, ``"NS"`` or ``"RS"``.
        region: a BSSA14 region of ``pygmm`` (``"global"``, ``"california"``, ...).
        periods: ``[P]`` periods in s within the model's 0.01-10 s.

    Returns:
        The target at ``periods``, medians converted from g to m/s^2; the median and
        sigma are interpolated in log-period between the model's own periods.
    """
    import pygmm
    from pygmm.baker_jayaram_2008 import calc_correls

    periods = np.asarray(periods, dtype=np.float64)
    model_periods = pygmm.BooreStewartSeyhanAtkinson2014.PERIODS[
        pygmm.BooreStewartSeyhanAtkinson2014.INDICES_PSA
    ]
    if periods.min() < model_periods.min() or periods.max() > model_periods.max():
        raise InputError(
            f"BSSA14 covers periods {model_periods.min():g}-{model_periods.max():g} s, "
            f"asked for {periods.min():g}-{periods.max():g} s"
        )
    scenario = pygmm.Scenario(
        mag=magnitude, dist_jb=rjb_km, v_s30=vs30, mechanism=mechanism, region=region
    )
    model = pygmm.BooreStewartSeyhanAtkinson2014(scenario)
    median = model.interp_spec_accels(periods) * STANDARD_GRAVITY
    ln_std = model.interp_ln_stds(periods)
    correlation = calc_correls(periods[:, None], periods[None, :])
    return TargetSpectrum(periods, median, ln_std, correlation)
