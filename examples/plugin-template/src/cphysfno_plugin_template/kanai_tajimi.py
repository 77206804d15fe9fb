"""Ground motion ``kanai-tajimi``: white noise filtered by a soil layer (Kanai 1957, Tajimi
1960).

Bedrock acceleration ``w(t)``, Gaussian white noise of two-sided power spectral density
``S0`` (m^2/s^3, autocorrelation ``2 pi S0 delta(tau)``), drives a soil column of
frequency ``w_g`` and damping ratio ``z_g``::

    x'' + 2 z_g w_g x' + w_g^2 x = -w(t),     a_g = w + x'' = -(2 z_g w_g x' + w_g^2 x)

and the ground acceleration ``a_g`` has the Kanai-Tajimi spectrum
:func:`kanai_tajimi_psd`.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
from cphysfno_core import GroundMotions, InputError
from cphysfno_core.plugin import GroundMotionSource, Params
from pydantic import Field, PositiveFloat, ValidationInfo, field_validator


def kanai_tajimi_psd(
    omega: np.ndarray, intensity: float, frequency: float, damping: float
) -> np.ndarray:
    """Two-sided PSD of the ground acceleration, m^2/s^3:
    ``S0 (w_g^4 + 4 z_g^2 w_g^2 w^2) / ((w_g^2 - w^2)^2 + 4 z_g^2 w_g^2 w^2)``.

    Args:
        omega: circular frequencies in rad/s.
        intensity: S0 in m^2/s^3.
        frequency: w_g in rad/s.
        damping: z_g.
    """
    w2 = np.asarray(omega, dtype=np.float64) ** 2
    g2 = frequency**2
    coupling = 4.0 * damping**2 * g2 * w2
    return intensity * (g2 * g2 + coupling) / ((g2 - w2) ** 2 + coupling)


def kanai_tajimi_variance(intensity: float, frequency: float, damping: float) -> float:
    """Stationary variance of the ground acceleration, ``pi S0 w_g (1 + 4 z_g^2) / (2 z_g)``
    in m^2/s^4 (the integral of :func:`kanai_tajimi_psd` over all frequencies)."""
    return math.pi * intensity * frequency * (1.0 + 4.0 * damping**2) / (2.0 * damping)


class KanaiTajimiParams(Params):
    """Parameters of :class:`KanaiTajimi` (defaults: firm soil, Housner and Jennings)."""

    spectral_intensity: PositiveFloat = Field(
        0.015, description="two-sided PSD S0 of the bedrock white noise, m^2/s^3"
    )
    ground_frequency: PositiveFloat = Field(15.6, description="soil frequency w_g, rad/s")
    ground_damping: PositiveFloat = Field(0.6, description="soil damping ratio z_g")
    dt: PositiveFloat = Field(0.01, description="sampling time step, s")
    duration: PositiveFloat = Field(30.0, description="record length, s")

    @field_validator("duration")
    @classmethod
    def _at_least_one_step(cls, duration: float, info: ValidationInfo) -> float:
        dt = info.data.get("dt")
        if dt is not None and duration < dt:
            raise ValueError(f"must be at least one time step dt = {dt} s, got {duration} s")
        return duration


class KanaiTajimi(GroundMotionSource):
    """Stationary Kanai-Tajimi ground accelerations, sampled exactly.

    The soil state ``(x, x')`` is advanced from sample to sample by the exact solution of
    its linear equation: the transition matrix ``exp(A dt)`` and a Gaussian increment whose
    covariance is the integral of the white noise through the soil over one step (Van
    Loan's matrix exponential). The samples therefore have exactly the autocorrelation of
    the continuous process at lags ``k dt``, with no integration error; their spectrum is
    the Kanai-Tajimi spectrum folded at the Nyquist frequency ``pi / dt``.

    Each record starts with the soil at rest (``a_g(0) = 0``) and becomes stationary
    within a few ``1 / (z_g w_g)`` s (0.1 s with the defaults). Records are sampled at
    ``0, dt, ..., duration``.
    """

    name = "kanai-tajimi"
    Params = KanaiTajimiParams

    @property
    def n_steps(self) -> int:
        """Samples per record, ``floor(duration / dt) + 1``."""
        return int(math.floor(self.params.duration / self.params.dt + 1e-9)) + 1

    def _soil(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Transition ``[2, 2]``, Cholesky factor of the step covariance ``[2, 2]`` and the
        map ``[2]`` from the soil state to ``a_g``."""
        p = self.params
        wg, zg = p.ground_frequency, p.ground_damping
        a = np.array([[0.0, 1.0], [-(wg**2), -2.0 * zg * wg]])
        noise = np.array([[0.0, 0.0], [0.0, 2.0 * math.pi * p.spectral_intensity]])
        blocks = scipy.linalg.expm(np.block([[-a, noise], [np.zeros((2, 2)), a.T]]) * p.dt)
        transition = blocks[2:, 2:].T
        covariance = transition @ blocks[:2, 2:]
        factor = scipy.linalg.cholesky(0.5 * (covariance + covariance.T), lower=True)
        return transition, factor, np.array([-(wg**2), -2.0 * zg * wg])

    def sample(self, n: int, rng: np.random.Generator) -> GroundMotions:
        """``n`` independent records, ``[n, n_steps]`` in m/s^2.

        Args:
            n: number of records (>= 1).
            rng: source of the Gaussian increments; the same state gives the same records.
        """
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise InputError(f"{self.name}: n must be a positive integer, got {n!r}")
        transition, factor, output = self._soil()
        increments = rng.standard_normal((self.n_steps - 1, int(n), 2)) @ factor.T
        state = np.zeros((int(n), 2))
        acceleration = np.zeros((int(n), self.n_steps))
        for k, increment in enumerate(increments, start=1):
            state = state @ transition.T + increment
            acceleration[:, k] = state @ output
        metadata = tuple({"source": self.name, "index": i} for i in range(int(n)))
        return GroundMotions(acceleration, self.params.dt, metadata)
