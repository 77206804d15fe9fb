"""Ground-motion intensity measures: response spectra, Sa_avg, PGA, PGV, Arias intensity,
D5-95.

Every function takes accelerations ``[n_records, n_steps]`` in m/s^2 (a 1-D array is one
record) with their time step ``dt`` in s, and treats each record as linear between its
samples, starting from rest at t = 0. Under that reading the integrals here are exact:
velocity and displacement by the exact double integral of a piecewise-linear function, the
Arias integral by the exact integral of its square, and the oscillator responses of the
response spectrum by the exact piecewise-linear recurrence of Nigam and Jennings (1969),
run as a second-order recursive filter along time over all records at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.signal

from .errors import InputError
from .histories import check_finite, check_time_step

STANDARD_GRAVITY = 9.80665
"""Standard acceleration of gravity g, m/s^2."""


def _records(acceleration: np.ndarray) -> np.ndarray:
    """``[n_records, n_steps]`` float64 view of ``acceleration``, or :class:`InputError`."""
    try:
        ag = np.asarray(acceleration, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError("acceleration must be a numeric array [n_records, n_steps]") from None
    if ag.ndim == 1:
        ag = ag[None, :]
    if ag.ndim != 2 or ag.shape[1] < 2:
        raise InputError(f"acceleration must have shape [n_records, n_steps >= 2], got {ag.shape}")
    check_finite(ag, "acceleration")
    return ag


def _periods(periods: np.ndarray | float) -> np.ndarray:
    values = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values) & (values > 0)):
        raise InputError(f"periods must be a 1-D array of finite values > 0 s, got {periods!r}")
    return values


def _check_damping(damping: float) -> float:
    value = float(damping)
    if not 0.0 <= value < 1.0:
        raise InputError(f"damping must be a ratio in [0, 1), got {damping!r}")
    return value


def _phi_functions(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``phi1(x) = (e^x - 1)/x`` and ``phi2(x) = (e^x - 1 - x)/x^2`` for complex ``x``,
    by their Taylor series where ``|x|`` is small and cancellation would cost digits."""
    small = np.abs(x) < 0.1
    safe = np.where(small, 1.0, x)
    series1, series2, term = np.ones_like(x), np.full_like(x, 0.5), np.ones_like(x)
    for k in range(1, 14):
        term = term * x / k
        series1 = series1 + term / (k + 1)
        series2 = series2 + term / ((k + 1) * (k + 2))
    phi1 = np.where(small, series1, np.expm1(safe) / safe)
    phi2 = np.where(small, series2, (np.expm1(safe) - safe) / safe**2)
    return phi1, phi2


def oscillator_filters(
    periods: np.ndarray, damping: float, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact one-step update of damped oscillators under piecewise-linear base acceleration.

    The oscillator ``u'' + 2 zeta w u' + w^2 u = -a(t)`` with ``a`` linear on each step has
    state ``x = [u, u']`` updated exactly by ``x_{k+1} = Phi x_k + B a_k + C a_{k+1}``
    (Nigam and Jennings 1969). The matrices are formed in closed form from the two complex
    eigenvalues ``lambda = -zeta w +- i w sqrt(1 - zeta^2)`` of the oscillator.

    Args:
        periods: ``[P]`` natural periods in s.
        damping: damping ratio zeta in [0, 1).
        dt: time step in s.

    Returns:
        ``(Phi [P, 2, 2], B [P, 2], C [P, 2])``; the displacement entries of B and C are in
        s^2, the velocity entries in s.
    """
    omega = 2.0 * np.pi / _periods(periods)
    zeta = _check_damping(damping)
    dt = check_time_step(dt)
    root = 1j * omega * np.sqrt(1.0 - zeta**2)
    lam = np.stack([-zeta * omega + root, -zeta * omega - root])
    step = np.exp(lam * dt)
    phi1, phi2 = _phi_functions(lam * dt)
    gap = lam[1] - lam[0]
    phi = np.empty((omega.size, 2, 2))
    phi[:, 0, 0] = ((lam[1] * step[0] - lam[0] * step[1]) / gap).real
    phi[:, 0, 1] = ((step[1] - step[0]) / gap).real
    phi[:, 1, 0] = ((lam[0] * lam[1] * (step[0] - step[1])) / gap).real
    phi[:, 1, 1] = ((lam[1] * step[1] - lam[0] * step[0]) / gap).real

    def forced(weights: np.ndarray) -> np.ndarray:
        """``V diag(weights) V^-1 g`` for the input vector ``g = [0, -1]``."""
        return np.stack(
            [
                ((weights[0] - weights[1]) / gap).real,
                ((lam[0] * weights[0] - lam[1] * weights[1]) / gap).real,
            ],
            axis=-1,
        )

    gain_value = forced(dt * phi1)
    gain_slope = forced(dt * phi2)
    return phi, gain_value - gain_slope, gain_slope


def _displacement(
    ag: np.ndarray, phi: np.ndarray, gain_b: np.ndarray, gain_c: np.ndarray
) -> np.ndarray:
    """``[n, T]`` displacement of one oscillator (update ``phi, gain_b, gain_c``) from rest.

    The displacement row of ``x_{k+1} = Phi x_k + B a_k + C a_{k+1}`` obeys a two-pole
    recurrence, run as a recursive filter along time. Started from a zero filter state, that
    filter answers as if the oscillator held ``x_0 = C a_0``; the free vibration from that
    state, ``[Phi^k C]_0 a_0``, is subtracted so that the oscillator starts at rest.
    """
    denominator = np.array([1.0, -np.trace(phi), np.linalg.det(phi)])
    numerator = np.array(
        [
            gain_c[0],
            gain_b[0] - phi[1, 1] * gain_c[0] + phi[0, 1] * gain_c[1],
            phi[0, 1] * gain_b[1] - phi[1, 1] * gain_b[0],
        ]
    )
    free_start = np.array([gain_c[0], (phi @ gain_c)[0] + denominator[1] * gain_c[0]])
    impulse = np.zeros(ag.shape[1])
    impulse[0] = 1.0
    free = scipy.signal.lfilter(free_start, denominator, impulse)
    forced = scipy.signal.lfilter(numerator, denominator, ag, axis=-1)
    forced -= ag[:, :1] * free
    return forced


def oscillator_displacement(
    acceleration: np.ndarray, dt: float, period: float, damping: float = 0.05
) -> np.ndarray:
    """Relative displacement history of one oscillator under every record, exact at the samples.

    Args:
        acceleration: ``[n, T]`` base accelerations in m/s^2, linear between samples.
        dt: time step in s.
        period: natural period of the oscillator in s.
        damping: damping ratio (0.05 is 5%).

    Returns:
        ``[n, T]`` relative displacement in m, starting at rest (0 at t = 0).
    """
    phi, gain_b, gain_c = oscillator_filters(np.array([period]), damping, dt)
    return _displacement(_records(acceleration), phi[0], gain_b[0], gain_c[0])


@dataclass(frozen=True)
class ResponseSpectrum:
    """Elastic response spectra of a batch of records.

    Attributes:
        periods: ``[P]`` oscillator periods in s.
        damping: damping ratio.
        displacement: ``[n, P]`` peak relative displacement SD in m.
    """

    periods: np.ndarray
    damping: float
    displacement: np.ndarray

    @property
    def pseudo_velocity(self) -> np.ndarray:
        """``[n, P]`` pseudo-spectral velocity PSV = w SD in m/s."""
        return self.displacement * (2.0 * np.pi / self.periods)

    @property
    def pseudo_acceleration(self) -> np.ndarray:
        """``[n, P]`` pseudo-spectral acceleration PSA = w^2 SD in m/s^2."""
        return self.displacement * (2.0 * np.pi / self.periods) ** 2


@dataclass(frozen=True)
class SpectrumBand:
    """A target response spectrum: its median and a band, e.g. 2.5 % to 97.5 %.

    Attributes:
        periods: ``[P]`` periods in s, increasing.
        median: ``[P]`` median pseudo-spectral acceleration in m/s^2.
        lower: ``[P]`` lower edge of the band in m/s^2.
        upper: ``[P]`` upper edge of the band in m/s^2.
        damping: damping ratio the spectra are defined for.
        label: what the band spans, for a legend.
    """

    periods: np.ndarray
    median: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    damping: float = 0.05
    label: str = "2.5 % and 97.5 %"

    def __post_init__(self) -> None:
        periods = _periods(self.periods)
        for name in ("median", "lower", "upper"):
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.shape != periods.shape:
                raise InputError(f"{name} must have one value per period, got {value.shape}")
            object.__setattr__(self, name, value)
        object.__setattr__(self, "periods", periods)
        _check_damping(self.damping)


def response_spectrum(
    acceleration: np.ndarray, dt: float, periods: np.ndarray, damping: float = 0.05
) -> ResponseSpectrum:
    """Response spectra of every record at every period (5% damping by default).

    Args:
        acceleration: ``[n, T]`` ground accelerations in m/s^2 (1-D: one record).
        dt: time step in s.
        periods: ``[P]`` oscillator periods in s (> 0).
        damping: damping ratio.

    Returns:
        The peak displacements ``[n, P]`` with PSV and PSA derived from them; peaks are
        taken over the samples.
    """
    ag = _records(acceleration)
    periods = _periods(periods)
    phi, gain_b, gain_c = oscillator_filters(periods, damping, dt)
    peaks = np.empty((ag.shape[0], periods.size))
    for j in range(periods.size):
        peaks[:, j] = np.abs(_displacement(ag, phi[j], gain_b[j], gain_c[j])).max(axis=1)
    return ResponseSpectrum(periods.copy(), _check_damping(damping), peaks)


def spectral_acceleration(
    acceleration: np.ndarray, dt: float, period: float, damping: float = 0.05
) -> np.ndarray:
    """``[n]`` the pseudo-spectral acceleration Sa(``period``) of every record, m/s^2
    (5 % damping by default): ``(2 pi / T)^2`` times the oscillator's peak displacement."""
    return response_spectrum(acceleration, dt, [period], damping).pseudo_acceleration[:, 0]


def average_spectral_acceleration(
    acceleration: np.ndarray,
    dt: float,
    low: float,
    high: float,
    n_periods: int = 10,
    damping: float = 0.05,
) -> np.ndarray:
    """``[n]`` average spectral acceleration Sa_avg in m/s^2: the geometric mean of the
    pseudo-spectral acceleration at ``n_periods`` periods spaced evenly in logarithm from
    ``low`` to ``high`` s (Eads, Miranda and Lignos 2015 take 0.2 T1 to 3 T1).

    Raises:
        InputError: ``low`` is not > 0, ``high`` is below ``low``, or ``n_periods < 1``.
    """
    if not (np.isfinite(low) and np.isfinite(high) and 0.0 < low <= high):
        raise InputError(f"need 0 < low <= high periods in s, got {low}, {high}")
    if int(n_periods) < 1:
        raise InputError(f"n_periods must be >= 1, got {n_periods}")
    periods = np.geomspace(low, high, int(n_periods))
    spectrum = response_spectrum(acceleration, dt, periods, damping).pseudo_acceleration
    with np.errstate(divide="ignore"):
        return np.exp(np.mean(np.log(spectrum), axis=1))


def velocity_displacement(acceleration: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Ground velocity and displacement from rest, exact for piecewise-linear acceleration.

    Returns:
        ``(velocity [n, T] in m/s, displacement [n, T] in m)``.
    """
    ag = _records(acceleration)
    dt = check_time_step(dt)
    velocity = np.zeros_like(ag)
    np.cumsum(0.5 * dt * (ag[:, 1:] + ag[:, :-1]), axis=1, out=velocity[:, 1:])
    step = dt * velocity[:, :-1] + dt**2 / 6.0 * (2.0 * ag[:, :-1] + ag[:, 1:])
    displacement = np.zeros_like(ag)
    np.cumsum(step, axis=1, out=displacement[:, 1:])
    return velocity, displacement


def peak_ground_acceleration(acceleration: np.ndarray) -> np.ndarray:
    """``[n]`` PGA, the largest absolute acceleration, in m/s^2."""
    return np.abs(_records(acceleration)).max(axis=1)


def peak_ground_velocity(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """``[n]`` PGV, the largest absolute ground velocity over the samples, in m/s."""
    velocity, _ = velocity_displacement(acceleration, dt)
    return np.abs(velocity).max(axis=1)


def cumulative_arias_intensity(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """``[n, T]`` Arias intensity accumulated up to each sample, ``pi/(2g) int a^2``, in m/s."""
    ag = _records(acceleration)
    dt = check_time_step(dt)
    left, right = ag[:, :-1], ag[:, 1:]
    pieces = dt / 3.0 * (left**2 + left * right + right**2)
    cumulative = np.zeros_like(ag)
    np.cumsum(pieces, axis=1, out=cumulative[:, 1:])
    return np.pi / (2.0 * STANDARD_GRAVITY) * cumulative


def arias_intensity(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """``[n]`` Arias intensity ``I_a = pi/(2g) int a(t)^2 dt`` over the record, in m/s."""
    return cumulative_arias_intensity(acceleration, dt)[:, -1]


def significant_duration(
    acceleration: np.ndarray, dt: float, start: float = 0.05, end: float = 0.95
) -> np.ndarray:
    """``[n]`` significant duration in s: the time between ``start`` and ``end`` fractions of
    the record's Arias intensity (D5-95 by default), interpolated between samples.

    A record with no motion at all has duration 0.
    """
    if not 0.0 <= start < end <= 1.0:
        raise InputError(f"need 0 <= start < end <= 1 (fractions of Arias), got {start}, {end}")
    cumulative = cumulative_arias_intensity(acceleration, dt)
    total = cumulative[:, -1:]
    fraction = np.divide(cumulative, total, out=np.zeros_like(cumulative), where=total > 0)
    duration = _crossing_time(fraction, end, dt) - _crossing_time(fraction, start, dt)
    return np.where(total[:, 0] > 0, duration, 0.0)


def _crossing_time(fraction: np.ndarray, level: float, dt: float) -> np.ndarray:
    """``[n]`` first time in s at which each non-decreasing row of ``fraction`` reaches
    ``level``, linear between samples (0 where the row never rises above 0)."""
    after = np.clip((fraction < level).sum(axis=1), 1, fraction.shape[1] - 1)
    rows = np.arange(fraction.shape[0])
    low, high = fraction[rows, after - 1], fraction[rows, after]
    rise = np.where(high > low, high - low, 1.0)
    share = np.clip((level - low) / rise, 0.0, 1.0)
    return (after - 1 + share) * float(dt)
