"""Band-limited Gaussian white noise synthesised as a sum of cosines (paper Eq. WN).

``a_g(t) = sigma * sum_{j=1}^{n/2} [X_j cos(w_j t) + X_{n/2+j} sin(w_j t)]`` with
``X ~ iid N(0, 1)``, ``w_j = j dw`` and ``sigma = sqrt(2 S dw)``: a stationary Gaussian
process whose two-sided power spectral density is ``S`` (m^2/s^3) on ``|w| <= w_cut``
with ``w_cut = (n/2) dw``, so its variance is ``2 S w_cut`` (m^2/s^4).
"""

from __future__ import annotations

import math

import numpy as np
from cphysfno_core import GroundMotions, InputError
from cphysfno_core.plugin import GroundMotionSource, Params
from pydantic import Field, PositiveFloat, ValidationInfo, field_validator


class WhiteNoiseParams(Params):
    """Parameters of :class:`WhiteNoise` (defaults: the paper's Example 1, §5.1)."""

    spectral_intensity: PositiveFloat = Field(
        0.015, description="two-sided power spectral density S of a_g, m^2/s^3"
    )
    spectral_intensity_range: tuple[PositiveFloat, PositiveFloat] | None = Field(
        None,
        description="(low, high) m^2/s^3: each record's S drawn log-uniformly in this range "
        "instead of spectral_intensity, for records that span intensities (fragility)",
    )
    n_terms: int = Field(
        1200, gt=0, description="number n of Gaussian coefficients (even): n/2 frequencies"
    )
    frequency_step: PositiveFloat = Field(
        math.pi / 30.0, description="spacing dw of the frequencies w_j = j dw, rad/s"
    )
    dt: PositiveFloat = Field(0.01, description="sampling time step, s")
    duration: PositiveFloat = Field(30.0, description="record length, s")

    @field_validator("spectral_intensity_range")
    @classmethod
    def _low_to_high(cls, value: tuple[float, float] | None) -> tuple[float, float] | None:
        if value is not None and value[0] > value[1]:
            raise ValueError(f"must be (low, high), got {value}")
        return value

    @field_validator("n_terms")
    @classmethod
    def _even(cls, n_terms: int) -> int:
        if n_terms % 2:
            raise ValueError(f"must be even (cosine and sine per frequency), got {n_terms}")
        return n_terms

    @field_validator("dt")
    @classmethod
    def _below_nyquist(cls, dt: float, info: ValidationInfo) -> float:
        n_terms = info.data.get("n_terms")
        step = info.data.get("frequency_step")
        if n_terms is None or step is None:
            return dt
        cutoff = n_terms // 2 * step
        nyquist = math.pi / dt
        if cutoff >= nyquist:
            raise ValueError(
                f"the cut-off frequency n_terms/2 * frequency_step = {cutoff:.6g} rad/s must be "
                f"below the Nyquist frequency pi/dt = {nyquist:.6g} rad/s: reduce dt to below "
                f"{math.pi / cutoff:.6g} s or lower n_terms or frequency_step"
            )
        return dt

    @field_validator("duration")
    @classmethod
    def _at_least_one_step(cls, duration: float, info: ValidationInfo) -> float:
        dt = info.data.get("dt")
        if dt is not None and duration < dt:
            raise ValueError(f"must be at least one time step dt = {dt} s, got {duration} s")
        return duration


class WhiteNoise(GroundMotionSource):
    """Stationary band-limited white-noise ground accelerations (paper Eq. WN).

    Records are sampled at ``0, dt, ..., duration`` (3001 samples with the defaults). With
    ``spectral_intensity_range`` each record has its own spectral density, drawn after
    its coefficients (so the records are those of the fixed density, each scaled by
    ``sqrt(S_i / spectral_intensity)``) and kept in its metadata.
    """

    name = "white-noise"
    independent_draws = True
    Params = WhiteNoiseParams

    @property
    def cutoff_frequency(self) -> float:
        """Highest frequency ``w_cut = (n_terms / 2) * frequency_step`` in rad/s."""
        return self.params.n_terms // 2 * self.params.frequency_step

    @property
    def n_steps(self) -> int:
        """Number of samples per record, ``floor(duration / dt) + 1``."""
        return int(math.floor(self.params.duration / self.params.dt + 1e-9)) + 1

    def sample(self, n: int, rng: np.random.Generator) -> GroundMotions:
        """``n`` independent records, ``[n, n_steps]`` in m/s^2, one matrix product.

        Args:
            n: number of records (>= 1).
            rng: source of the Gaussian coefficients; the same generator state gives the
                same records.
        """
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise InputError(f"white-noise: n must be a positive integer, got {n!r}")
        p = self.params
        half = p.n_terms // 2
        omega = p.frequency_step * np.arange(1, half + 1)
        phase = np.outer(omega, np.arange(self.n_steps) * p.dt)
        basis = np.concatenate([np.cos(phase), np.sin(phase)])
        coefficients = rng.standard_normal((int(n), p.n_terms))
        metadata = [{"source": self.name, "index": i} for i in range(int(n))]
        intensity = np.full(int(n), p.spectral_intensity)
        if p.spectral_intensity_range is not None:
            low, high = np.log(p.spectral_intensity_range)
            intensity = np.exp(rng.uniform(low, high, size=int(n)))
            for meta, value in zip(metadata, intensity, strict=True):
                meta["spectral_intensity"] = float(value)
        sigma = np.sqrt(2.0 * intensity * p.frequency_step)
        acceleration = sigma[:, None] * (coefficients @ basis)
        return GroundMotions(acceleration, p.dt, tuple(metadata))
