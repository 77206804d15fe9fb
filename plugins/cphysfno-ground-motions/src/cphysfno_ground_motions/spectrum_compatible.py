"""Spectrum-compatible synthetic accelerograms (paper §5.2).

Each record gets its own target spectrum, drawn from the BSSA14 ground-motion model for a
scenario with ordinates correlated across periods by Baker and Jayaram (2008)
(:mod:`.target`). It starts as a Fourier series with random phases and amplitudes shaped
like that target, modulated by the Jennings, Housner and Tsai (1968) envelope; its
amplitudes are adjusted in the frequency domain, then wavelets are added at its peak
responses (:mod:`.matching`), until its 5%-damped PSA matches the target within
``tolerance`` at ``n_periods`` periods spread log-uniformly over ``period_band``. A baseline
correction inside every iteration brings the final ground velocity and displacement to
zero (:mod:`.baseline`), so the spectrum checked is the corrected record's.

PSA at short periods cannot fall much below the PGA, and the largest PSA of a random-phase
record is typically 2.5 times its PGA, rarely more than 4; a draw whose mid-period ordinates
stand far above its shortest-period one asks for more. The time-domain stage therefore
holds the PGA at the shortest-period target, and a record still left outside the tolerance
is tried again with new phases, each retry clipping its stationary series at a lower crest
factor (:data:`RETRY_CREST_FACTORS`), which raises the PSA reached per unit of PGA. Records
still outside after ``retries`` (about 1% of draws from the default scenario, most of them
asking for a largest PSA over 6 times the shortest-period one) keep their best attempt and
are counted in a warning; each record's misfit is in its metadata.
"""

from __future__ import annotations

import math
import warnings
from functools import cached_property
from typing import Literal

import numpy as np
from cphysfno_core import GroundMotions, InputError
from cphysfno_core.plugin import GroundMotionSource, Params
from cphysfno_core.signals.intensity import SpectrumBand
from pydantic import Field, PositiveFloat, ValidationInfo, field_validator

from .errors import GroundMotionWarning
from .matching import match_spectra, series_frequencies
from .record_measures import intensity_metadata
from .target import TargetSpectrum, bssa14_target

RETRY_CREST_FACTORS = (2.0, 1.6, 1.3, 1.1)
"""Crest factor, in standard deviations, at which each retry clips its stationary series."""


class SpectrumCompatibleParams(Params):
    """Parameters of :class:`SpectrumCompatible`; defaults are the stated scenario
    M 7.0 strike-slip at R_JB = 20 km on V_S30 = 400 m/s ground (California), records of
    30 s at dt = 0.01 s (3001 samples) matched within 10% at 20 periods over 0.1-5 s."""

    magnitude: float = Field(7.0, ge=3.0, le=8.5, description="moment magnitude M (BSSA14)")
    rjb_km: float = Field(20.0, ge=0.0, le=300.0, description="Joyner-Boore distance, km")
    vs30: float = Field(400.0, ge=150.0, le=1500.0, description="V_S30 of the site, m/s")
    mechanism: Literal["U", "SS", "NS", "RS"] = Field(
        "SS", description="U unspecified, SS strike-slip, NS normal, RS reverse"
    )
    region: Literal[
        "global", "california", "china", "italy", "japan", "new_zealand", "taiwan", "turkey"
    ] = Field("california", description="BSSA14 regional attenuation and basin model")
    variability: bool = Field(
        True,
        description="draw each record's target from the model's correlated lognormal "
        "distribution (False: every record matches the median)",
    )
    dt: PositiveFloat = Field(0.01, description="time step, s")
    duration: PositiveFloat = Field(30.0, description="record length, s")
    period_band: tuple[PositiveFloat, PositiveFloat] = Field(
        (0.1, 5.0), validate_default=True, description="shortest and longest matching period, s"
    )
    n_periods: int = Field(20, ge=2, le=50, description="matching periods in the band")
    tolerance: float = Field(
        0.1,
        gt=0.0,
        lt=1.0,
        description="largest accepted misfit: every PSA in the band within a factor "
        "1 + tolerance of its target",
    )
    max_iterations: int = Field(
        10, ge=0, le=500, description="most frequency-domain amplitude adjustments per record"
    )
    wavelet_iterations: int = Field(
        40, ge=0, le=500, description="most time-domain wavelet adjustments per record"
    )
    retries: int = Field(
        len(RETRY_CREST_FACTORS),
        ge=0,
        le=len(RETRY_CREST_FACTORS),
        description="new attempts, with new phases, for records left outside the tolerance",
    )
    rise_time: PositiveFloat = Field(2.0, description="envelope rise (t/t1)^2 until t1, s")
    strong_duration: PositiveFloat = Field(
        10.0, description="length of the envelope's plateau after the rise, s"
    )
    decay_rate: PositiveFloat = Field(
        0.3, description="exponential decay rate of the envelope after the plateau, 1/s"
    )

    @field_validator("period_band")
    @classmethod
    def _ordered_in_model(
        cls, band: tuple[float, float], info: ValidationInfo
    ) -> tuple[float, float]:
        low, high = band
        if not low < high:
            raise ValueError(f"needs shortest < longest period, got {band}")
        if low < 0.01 or high > 10.0:
            raise ValueError(f"must lie within BSSA14's 0.01-10 s, got {band}")
        dt = info.data.get("dt")
        if dt is not None and low < 2 * dt:
            raise ValueError(
                f"shortest period {low} s is below the Nyquist period 2 dt = {2 * dt} s"
            )
        duration = info.data.get("duration")
        if duration is not None and 2 * high > duration:
            raise ValueError(
                f"longest period {high} s needs a record of two of its cycles, {2 * high} s, "
                f"longer than duration = {duration} s"
            )
        return band

    @field_validator("duration")
    @classmethod
    def _long_enough(cls, duration: float, info: ValidationInfo) -> float:
        dt = info.data.get("dt")
        if dt is not None and duration < 10 * dt:
            raise ValueError(f"must hold at least 10 time steps of {dt} s, got {duration} s")
        return duration


def jennings_envelope(
    time: np.ndarray, rise_time: float, strong_duration: float, decay_rate: float
) -> np.ndarray:
    """``[T]`` envelope: ``(t/t1)^2`` up to ``t1``, 1 until ``t2 = t1 + strong_duration``,
    then ``exp(-decay_rate (t - t2))`` (Jennings, Housner and Tsai 1968)."""
    end_of_plateau = rise_time + strong_duration
    rise = (time / rise_time) ** 2
    decay = np.exp(-decay_rate * np.clip(time - end_of_plateau, 0.0, None))
    return np.where(time < rise_time, rise, decay)


class SpectrumCompatible(GroundMotionSource):
    """Synthetic accelerograms each matched to its own BSSA14 target spectrum (paper §5.2).

    ``sample(n, rng)`` returns ``[n, round(duration / dt) + 1]`` records in m/s^2 with
    metadata: the scenario, each record's sampled target (``target_psa`` in m/s^2 at
    ``matching_periods`` in s), its matching misfit (``match_misfit``, computed on the
    baseline-corrected record), adjustments (``match_iterations``) and attempts
    (``match_attempts``, 1 when no retry was needed), and PGA, PGV, Arias intensity and
    D5-95.
    """

    name = "spectrum-compatible"
    independent_draws = True
    Params = SpectrumCompatibleParams

    @property
    def n_steps(self) -> int:
        """Samples per record."""
        return int(round(self.params.duration / self.params.dt)) + 1

    @property
    def matching_periods(self) -> np.ndarray:
        """``[P]`` periods in s at which the spectra are matched, log-uniform over the band."""
        low, high = self.params.period_band
        return np.geomspace(low, high, self.params.n_periods)

    @cached_property
    def target(self) -> TargetSpectrum:
        """The scenario's BSSA14 / Baker-Jayaram target at :attr:`matching_periods`."""
        p = self.params
        return bssa14_target(
            p.magnitude, p.rjb_km, p.vs30, p.mechanism, p.region, self.matching_periods
        )

    def target_spectrum(self) -> SpectrumBand:
        """The target's median and 2.5-97.5 % band at the matching periods (m/s^2)."""
        return self.target.band()

    def sample(self, n: int, rng: np.random.Generator) -> GroundMotions:
        """``n`` matched records; the same generator state gives the same records.

        Draws, in order: the ``[n, P]`` target spectra (when ``variability``), the ``[n, F]``
        phases uniform on [0, 2 pi), then ``[m, F]`` new phases for the ``m`` records each
        retry takes up. Warns once (:class:`GroundMotionWarning`) when records end outside
        the tolerance after every retry, with their count and the worst misfit.
        """
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise InputError(f"{self.name}: n must be a positive integer, got {n!r}")
        p = self.params
        n = int(n)
        periods = self.matching_periods
        spectra = (
            self.target.sample(n, rng) if p.variability else np.tile(self.target.median, (n, 1))
        )
        acceleration, misfit, iterations, attempts = self._match(spectra, rng)
        outside = np.flatnonzero(misfit > p.tolerance)
        if outside.size:
            warnings.warn(
                f"{self.name}: {outside.size} of {n} records end outside the tolerance "
                f"{p.tolerance:g} after {p.retries} retries (records {outside[:10].tolist()}"
                f"{'...' if outside.size > 10 else ''}, worst misfit {misfit.max():.3f}); "
                "each record's match_misfit is in its metadata",
                GroundMotionWarning,
                stacklevel=2,
            )
        scenario = {
            "source": self.name,
            "magnitude": p.magnitude,
            "rjb_km": p.rjb_km,
            "vs30": p.vs30,
            "mechanism": p.mechanism,
        }
        measures = intensity_metadata(acceleration, p.dt)
        metadata = [
            {
                **scenario,
                "index": i,
                "matching_periods": tuple(periods.tolist()),
                "target_psa": tuple(spectra[i].tolist()),
                "match_misfit": float(misfit[i]),
                "match_iterations": int(iterations[i]),
                "match_attempts": int(attempts[i]),
                **measures[i],
            }
            for i in range(n)
        ]
        return GroundMotions(acceleration, p.dt, metadata)

    def _match(
        self, spectra: np.ndarray, rng: np.random.Generator
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Records matched to ``spectra`` ``[n, P]`` (m/s^2), retrying those left outside
        the tolerance; returns their accelerations ``[n, T]``, misfits, adjustments and
        attempts, each record keeping its best attempt."""
        p = self.params
        n = spectra.shape[0]
        frequencies = series_frequencies(self.n_steps, p.dt)
        amplitude = self._starting_amplitude(spectra, frequencies)
        time = np.arange(self.n_steps) * p.dt
        envelope = jennings_envelope(time, p.rise_time, p.strong_duration, p.decay_rate)
        acceleration = np.zeros((n, self.n_steps))
        misfit = np.full(n, np.inf)
        iterations = np.zeros(n, dtype=int)
        attempts = np.zeros(n, dtype=int)
        todo = np.arange(n)
        for crest_factor in (None, *RETRY_CREST_FACTORS[: p.retries]):
            phase = rng.uniform(0.0, 2.0 * math.pi, size=(todo.size, frequencies.size))
            result = match_spectra(
                amplitude[todo],
                phase,
                envelope,
                p.dt,
                self.matching_periods,
                spectra[todo],
                tolerance=p.tolerance,
                frequency_iterations=p.max_iterations,
                wavelet_iterations=p.wavelet_iterations,
                damping=self.target.damping,
                crest_factor=crest_factor,
            )
            better = result.misfit < misfit[todo]
            kept = todo[better]
            acceleration[kept] = result.acceleration[better]
            misfit[kept] = result.misfit[better]
            iterations[kept] = result.iterations[better]
            attempts[todo] += 1
            todo = todo[misfit[todo] > p.tolerance]
            if not todo.size:
                break
        return acceleration, misfit, iterations, attempts

    def _starting_amplitude(self, spectra: np.ndarray, frequencies: np.ndarray) -> np.ndarray:
        """``[n, F]`` first amplitudes: each target spectrum read at ``1 / f`` (held beyond
        the band), zero below half the band's lowest frequency and raised to full by a
        half-cosine up to that frequency."""
        low_frequency = 1.0 / self.params.period_band[1]
        floor = 0.5 * low_frequency
        ramp = np.clip((frequencies - floor) / (low_frequency - floor), 0.0, 1.0)
        taper = 0.5 - 0.5 * np.cos(np.pi * ramp)
        order = np.argsort(1.0 / self.matching_periods)
        nodes = np.log(1.0 / self.matching_periods[order])
        safe = np.log(np.maximum(frequencies, frequencies[1]))
        shape = np.stack([np.interp(safe, nodes, np.log(row[order])) for row in spectra])
        return np.exp(shape) * taper
