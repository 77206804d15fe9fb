"""Spectral matching of modulated Fourier series to per-record target spectra, all records at
once, in two stages.

1. **Frequency domain.** Each record is ``a(t) = baseline(e(t) s(t))``: a stationary Fourier
   series ``s`` with amplitudes ``A_j`` and phases ``phi_j`` at the frequencies
   ``f_j = j / (N dt)``, modulated by the envelope ``e`` and baseline corrected. The series
   repeats only after ``N >= PADDING T`` samples, so that several lines lie between
   neighbouring long matching periods. Every iteration computes the record's 5%-damped PSA
   at the matching periods and multiplies the amplitudes by ``target / PSA`` interpolated
   linearly in log frequency: in full for the record's overall level (the mean log ratio;
   exact, since PSA is proportional to scale) and raised to :data:`FREQUENCY_STEP` for its
   shape. Phases are kept, unless a crest-factor limit is given: then the series is clipped
   at that many standard deviations and takes the clipped series' phases with its own
   amplitudes, which lowers the PGA a given spectrum needs.
2. **Time domain** (Al Atik and Abrahamson 2010). At each matching period ``T_i`` the
   oscillator's peak response ``R_i``, at sample ``k_i``, is moved to the target by adding
   improved tapered cosine wavelets, one per period, each centred so that its own
   oscillator answers it in phase at the peak it adjusts. Their amplitudes solve the
   ``P x P`` linear system of every wavelet's effect on every peak, written in changes
   relative to the targets and solved by a truncated singular value decomposition
   (:data:`SINGULAR_CUTOFF`), and are relaxed by :data:`WAVELET_STEP`. After every
   iteration the ground acceleration is clipped at the target PSA of the shortest matching
   period: PSA tends to the PGA as the period shrinks, so a PGA above that ordinate keeps
   it out of reach, and peaks at short periods fall together at the PGA, where wavelets
   lower one at a time. The wavelets carry almost no content near zero frequency, so the
   baseline correction repeated after every iteration barely moves the spectrum, and the
   spectrum checked is always that of the corrected record.

A record's misfit is ``exp(max |ln(PSA / target)|) - 1`` over the periods: within a
tolerance of 0.1, every ordinate lies between ``target / 1.1`` and ``1.1 target``. A record
leaves a stage when its misfit is within the tolerance, or when its misfit has not fallen by
:data:`MIN_IMPROVEMENT` for the stage's patience; each stage returns every record's best
iterate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft
from cphysfno_core.signals.intensity import oscillator_displacement, response_spectrum

from .baseline import baseline_correct

PADDING = 4
"""The stationary series repeats after at least this many record lengths."""

FREQUENCY_STEP = 0.8
"""Exponent applied to the shape of ``target / PSA`` in a frequency-domain update."""

WAVELET_STEP = 0.5
"""Share of the solved wavelet amplitudes added in a time-domain iteration."""

FREQUENCY_PATIENCE = 4
"""Frequency-domain iterations without improvement after which a record leaves the stage."""

WAVELET_PATIENCE = 12
"""Time-domain iterations without improvement after which a record leaves the stage."""

MIN_IMPROVEMENT = 0.005
"""Decrease of the misfit that counts as an improvement."""

WAVELET_SPAN = 3.5
"""Half-length of a wavelet in units of its Gaussian width ``gamma``."""

SINGULAR_CUTOFF = 1e-2
"""Singular values of the wavelet system below this share of the largest are left out:
peaks that fall at one instant (short periods following the ground acceleration) ask for
nearly the same change, and their differences are not solved for."""


@dataclass(frozen=True)
class MatchResult:
    """Matched records.

    Attributes:
        acceleration: ``[n, T]`` matched, baseline-corrected accelerations in m/s^2.
        misfit: ``[n]`` ``exp(max |ln(PSA / target)|) - 1`` over the matching periods.
        iterations: ``[n]`` adjustments made for each record.
    """

    acceleration: np.ndarray
    misfit: np.ndarray
    iterations: np.ndarray


def series_length(steps: int) -> int:
    """Samples after which the stationary series behind records of ``steps`` samples
    repeats: the first length at least ``PADDING steps`` with small prime factors (fast FFT)."""
    return scipy.fft.next_fast_len(PADDING * steps, real=True)


def series_frequencies(steps: int, dt: float) -> np.ndarray:
    """``[F]`` frequencies in Hz of the stationary series behind records of ``steps``
    samples every ``dt`` s: ``j / (N dt)``, ``j = 0 .. N // 2``, ``N = series_length(steps)``."""
    return np.fft.rfftfreq(series_length(steps), dt)


def interpolation_weights(frequencies: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """``[F, P]`` weights that interpolate values at ``nodes`` (Hz, any order) linearly in
    log frequency onto ``frequencies`` (Hz, > 0), holding the end values beyond the nodes."""
    order = np.argsort(nodes)
    log_nodes = np.log(nodes[order])
    position = np.interp(np.log(frequencies), log_nodes, np.arange(nodes.size))
    lower = np.floor(position).astype(int).clip(0, nodes.size - 1)
    upper = np.minimum(lower + 1, nodes.size - 1)
    share = position - lower
    weights = np.zeros((frequencies.size, nodes.size))
    rows = np.arange(frequencies.size)
    np.add.at(weights, (rows, order[lower]), 1.0 - share)
    np.add.at(weights, (rows, order[upper]), share)
    return weights


def peak_responses(
    records: np.ndarray, dt: float, periods: np.ndarray, damping: float
) -> tuple[np.ndarray, np.ndarray]:
    """Each oscillator's largest relative displacement, with its sign, and when it occurs.

    Args:
        records: ``[n, T]`` accelerations in m/s^2.
        dt: time step in s.
        periods: ``[P]`` oscillator periods in s.
        damping: damping ratio.

    Returns:
        ``(value [n, P] in m, index [n, P])``: ``|value|`` is the spectral displacement of
        :func:`cphysfno_core.signals.intensity.response_spectrum`, reached at sample ``index``.
    """
    n = records.shape[0]
    value = np.empty((n, periods.size))
    index = np.empty((n, periods.size), dtype=int)
    rows = np.arange(n)
    for j, period in enumerate(periods):
        displacement = oscillator_displacement(records, dt, float(period), damping)
        index[:, j] = np.abs(displacement).argmax(axis=1)
        value[:, j] = displacement[rows, index[:, j]]
    return value, index


class _Progress:
    """The best iterate of every record, its misfit, and when it last improved."""

    def __init__(self, records: np.ndarray) -> None:
        self.best = records.copy()
        self.misfit = np.full(records.shape[0], np.inf)
        self.iterations = np.zeros(records.shape[0], dtype=int)
        self.last_improvement = np.zeros(records.shape[0], dtype=int)

    def update(
        self, rows: np.ndarray, records: np.ndarray, misfit: np.ndarray, iteration: int
    ) -> None:
        """Take in the iterate ``records`` of ``rows`` and its ``misfit``."""
        better = misfit < self.misfit[rows]
        self.best[rows[better]] = records[better]
        self.last_improvement[rows[misfit < self.misfit[rows] - MIN_IMPROVEMENT]] = iteration
        self.misfit[rows[better]] = misfit[better]
        self.iterations[rows] = iteration

    def going_on(
        self, rows: np.ndarray, misfit: np.ndarray, tolerance: float, iteration: int, patience: int
    ) -> np.ndarray:
        """``[len(rows)]`` whether each record is outside the tolerance and still improving."""
        return (misfit > tolerance) & (iteration - self.last_improvement[rows] < patience)

    def result(self) -> MatchResult:
        return MatchResult(self.best, self.misfit, self.iterations)


def _limit_crest(coefficients: np.ndarray, length: int, steps: int, crest: float) -> np.ndarray:
    """Coefficients with their amplitudes and the phases of their series clipped at
    ``crest`` times its standard deviation over the first ``steps`` samples."""
    series = np.fft.irfft(coefficients, n=length, axis=-1)
    limit = crest * series[:, :steps].std(axis=1, keepdims=True)
    clipped = np.fft.rfft(np.clip(series, -limit, limit), axis=-1)
    return np.abs(coefficients) * np.exp(1j * np.angle(clipped))


def match_amplitudes(
    amplitude: np.ndarray,
    phase: np.ndarray,
    envelope: np.ndarray,
    dt: float,
    periods: np.ndarray,
    target: np.ndarray,
    *,
    tolerance: float,
    max_iterations: int,
    damping: float = 0.05,
    crest_factor: float | None = None,
) -> MatchResult:
    """Adjust Fourier amplitudes until each record's PSA is near its own target spectrum.

    Args:
        amplitude: ``[n, F]`` starting amplitudes of the stationary series at
            :func:`series_frequencies`; a zero amplitude stays zero.
        phase: ``[n, F]`` phases in rad.
        envelope: ``[T]`` modulating function, also the shape of the baseline correction.
        dt: time step in s.
        periods: ``[P]`` matching periods in s.
        target: ``[n, P]`` target PSA of each record in m/s^2.
        tolerance: misfit at which a record is done.
        max_iterations: most amplitude adjustments per record.
        damping: damping ratio of the spectra.
        crest_factor: if given, after every adjustment the series takes the phases of its
            copy clipped at this many standard deviations.

    Returns:
        The best iterate of each record, its misfit and the adjustments it took.
    """
    steps = envelope.size
    length = series_length(steps)
    if amplitude.shape[1] != length // 2 + 1:
        raise ValueError(
            f"amplitudes must be given at {length // 2 + 1} frequencies for {steps} samples, "
            f"got {amplitude.shape[1]}"
        )
    frequencies = series_frequencies(steps, dt)
    weights = interpolation_weights(np.maximum(frequencies, frequencies[1]), 1.0 / periods)
    coefficients = amplitude * np.exp(1j * phase)
    progress = _Progress(np.zeros((amplitude.shape[0], steps)))
    active = np.arange(amplitude.shape[0])
    for iteration in range(max_iterations + 1):
        series = np.fft.irfft(coefficients[active], n=length, axis=-1)[:, :steps]
        records = baseline_correct(series * envelope, dt, envelope)
        psa = response_spectrum(records, dt, periods, damping).pseudo_acceleration
        ratio = np.log(psa / target[active])
        misfit = np.expm1(np.abs(ratio).max(axis=1))
        progress.update(active, records, misfit, iteration)
        keep = progress.going_on(active, misfit, tolerance, iteration, FREQUENCY_PATIENCE)
        if iteration == max_iterations or not keep.any():
            break
        active, ratio = active[keep], ratio[keep]
        level = ratio.mean(axis=1, keepdims=True)
        step = level + FREQUENCY_STEP * (ratio - level)
        coefficients[active] *= np.exp(-step @ weights.T)
        if crest_factor is not None:
            coefficients[active] = _limit_crest(coefficients[active], length, steps, crest_factor)
    return progress.result()


@dataclass(frozen=True)
class WaveletBasis:
    """Improved tapered cosine wavelets (Al Atik and Abrahamson 2010), one per matching
    period, and every oscillator's answer to each.

    Wavelet ``j`` is ``cos(w'_j tau) exp(-(tau / gamma_j)^2)`` with ``tau`` the time from its
    centre, ``w'_j = w_j sqrt(1 - zeta^2)``, ``gamma_j = 1.178 f_j^-0.93`` (s, ``f_j`` in
    Hz), cut at ``WAVELET_SPAN gamma_j``; its centre lies ``dt_j = atan(sqrt(1 - zeta^2) /
    zeta) / w'_j`` before the peak it adjusts.

    Attributes:
        templates: per period, the ``[2 H_j + 1]`` wavelet samples in m/s^2 per unit.
        shift: ``[P]`` samples from a wavelet's centre to its peak, ``round(dt_j / dt)``.
        answers: ``[P, P, L]`` displacement in m of oscillator ``i`` under unit wavelet ``j``
            at ``l - origin`` samples after the wavelet's centre, from rest.
        origin: the sample of ``answers`` at a wavelet's centre.
    """

    templates: tuple[np.ndarray, ...]
    shift: np.ndarray
    answers: np.ndarray
    origin: int

    @classmethod
    def build(cls, periods: np.ndarray, damping: float, dt: float, steps: int) -> WaveletBasis:
        """The wavelets at ``periods`` (s) for records of ``steps`` samples every ``dt`` s."""
        omega = 2.0 * np.pi / periods
        damped = omega * np.sqrt(1.0 - damping**2)
        gamma = 1.178 * (omega / (2.0 * np.pi)) ** -0.93
        shift = np.round(np.arctan(np.sqrt(1.0 - damping**2) / damping) / damped / dt)
        halves = np.ceil(WAVELET_SPAN * gamma / dt).astype(int)
        templates = []
        for frequency, width, half in zip(damped, gamma, halves, strict=True):
            tau = np.arange(-half, half + 1) * dt
            templates.append(np.cos(frequency * tau) * np.exp(-((tau / width) ** 2)))
        origin = int(halves.max())
        length = origin + max(steps + int(shift.max()), origin) + 1
        placed = np.zeros((periods.size, length))
        for j, (template, half) in enumerate(zip(templates, halves, strict=True)):
            placed[j, origin - half : origin + half + 1] = template
        answers = np.stack(
            [oscillator_displacement(placed, dt, float(p), damping) for p in periods]
        )
        return cls(tuple(templates), shift.astype(int), answers, origin)

    def effects(self, index: np.ndarray) -> np.ndarray:
        """``[m, P, P]``: the change in m of oscillator ``i``'s response at its peak sample
        ``index[:, i]`` per unit of wavelet ``j`` aimed at ``index[:, j]``."""
        periods = np.arange(index.shape[1])
        lag = index[:, :, None] - (index - self.shift)[:, None, :] + self.origin
        lag = np.clip(lag, 0, self.answers.shape[2] - 1)
        return self.answers[periods[:, None], periods[None, :], lag]

    def synthesize(self, index: np.ndarray, amplitude: np.ndarray, steps: int) -> np.ndarray:
        """``[m, steps]`` the sum of the wavelets aimed at ``index`` ``[m, P]`` with
        ``amplitude`` ``[m, P]`` (m/s^2), cut to the record."""
        margin = self.origin + int(self.shift.max())
        total = np.zeros((index.shape[0], steps + 2 * margin))
        rows = np.arange(index.shape[0])[:, None]
        for j, template in enumerate(self.templates):
            half = template.size // 2
            start = index[:, j] - self.shift[j] - half + margin
            total[rows, start[:, None] + np.arange(template.size)] += (
                amplitude[:, j, None] * template
            )
        return total[:, margin : margin + steps]


def match_wavelets(
    records: np.ndarray,
    envelope: np.ndarray,
    dt: float,
    periods: np.ndarray,
    target: np.ndarray,
    *,
    tolerance: float,
    max_iterations: int,
    damping: float = 0.05,
) -> MatchResult:
    """Add wavelets at the peak responses until each record's PSA matches its own target.

    Args:
        records: ``[n, T]`` accelerations in m/s^2, already near their targets; those it
            adjusts end with a PGA at most their target PSA at the shortest period.
        envelope: ``[T]`` the records' envelope: the shape of the baseline correction, and,
            up to its maximum, a taper that keeps the records' start quiet.
        dt: time step in s.
        periods: ``[P]`` matching periods in s.
        target: ``[n, P]`` target PSA of each record in m/s^2.
        tolerance: misfit at which a record is done.
        max_iterations: most wavelet adjustments per record.
        damping: damping ratio of the spectra.

    Returns:
        The best iterate of each record (the given record if none is better), its misfit
        and the adjustments it took.
    """
    steps = records.shape[1]
    basis = WaveletBasis.build(periods, damping, dt, steps)
    taper = np.maximum.accumulate(envelope) / envelope.max()
    wanted_peak = target / (2.0 * np.pi / periods) ** 2
    ceiling = target[:, np.argmin(periods)]
    current = np.array(records, dtype=np.float64)
    progress = _Progress(current)
    active = np.arange(current.shape[0])
    for iteration in range(max_iterations + 1):
        value, index = peak_responses(current[active], dt, periods, damping)
        misfit = np.expm1(np.abs(np.log(np.abs(value) / wanted_peak[active])).max(axis=1))
        progress.update(active, current[active], misfit, iteration)
        keep = progress.going_on(active, misfit, tolerance, iteration, WAVELET_PATIENCE)
        if iteration == max_iterations or not keep.any():
            break
        active, value, index = active[keep], value[keep], index[keep]
        peak = wanted_peak[active]
        effects = basis.effects(index)
        own = np.diagonal(effects, axis1=1, axis2=2)
        relative = effects / own[:, None, :] * peak[:, None, :] / peak[:, :, None]
        wanted = np.sign(value) * (1.0 - np.abs(value) / peak)
        solved = np.linalg.pinv(relative, rcond=SINGULAR_CUTOFF) @ wanted[..., None]
        amplitude = WAVELET_STEP * solved[..., 0] * peak / own
        adjusted = current[active] + taper * basis.synthesize(index, amplitude, steps)
        limit = ceiling[active, None]
        current[active] = baseline_correct(np.clip(adjusted, -limit, limit), dt, envelope)
    return progress.result()


def match_spectra(
    amplitude: np.ndarray,
    phase: np.ndarray,
    envelope: np.ndarray,
    dt: float,
    periods: np.ndarray,
    target: np.ndarray,
    *,
    tolerance: float,
    frequency_iterations: int,
    wavelet_iterations: int,
    damping: float = 0.05,
    crest_factor: float | None = None,
) -> MatchResult:
    """Both stages: :func:`match_amplitudes` for at most ``frequency_iterations``
    adjustments (with ``crest_factor``), then :func:`match_wavelets` on its result for at
    most ``wavelet_iterations``; the other arguments are those of :func:`match_amplitudes`.

    Returns:
        The matched records, their misfits, and the adjustments of both stages together.
    """
    first = match_amplitudes(
        amplitude,
        phase,
        envelope,
        dt,
        periods,
        target,
        tolerance=tolerance,
        max_iterations=frequency_iterations,
        damping=damping,
        crest_factor=crest_factor,
    )
    second = match_wavelets(
        first.acceleration,
        envelope,
        dt,
        periods,
        target,
        tolerance=tolerance,
        max_iterations=wavelet_iterations,
        damping=damping,
    )
    return MatchResult(second.acceleration, second.misfit, first.iterations + second.iterations)
