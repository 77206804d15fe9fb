"""The stick's law chosen by its dynamic response: probe pulses that drive the structure
itself through the drifts of the cyclic pushover, and each candidate law's stick against
the structure's response to them. The same pulses tell whether the stick may run on the
central-difference integrator (:func:`integrator_error`).

A law's fit to the pushovers is static: two laws that fit the story curves about as well
can part once the structure vibrates through them (on the two-story IMK frame the
`pinching` law fits the pushovers best and is twice as far from the frame under records
as a softening Bouc-Wen law). The probes are resonant pulses at the structure's first
period, ``sin(2 pi t / T1)`` under a Gaussian envelope (centre ``4 T1``, width ``1.5 T1``,
``12 T1`` long), each scaled so that the stick of the pushover-chosen law reaches one
roof drift ratio; the structure is analysed once on them.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from cphysfno_core import CphysfnoWarning, GroundMotions
from cphysfno_core.plugin import Structure

from .stick_calibration import StickCalibration

PROBE_SAMPLES_PER_PERIOD = 50
"""Samples of a probe per first period (and no step longer than 0.01 s)."""

SCALE_HALVINGS = 30
"""Bisection steps on each probe's scale (in its logarithm)."""

FOLLOWS = 0.03
"""Relative L2 within which a stick follows the structure: closer than that, the stick and
the structure differ by about what their integrators do (Newmark's rule against
Runge-Kutta at 5-10 ms, 2e-3 to 4e-2), so a closer fit would fit that instead of the
structure's physics."""

INTEGRATOR_TOLERANCE = 0.02
"""Largest :func:`integrator_error` at which the stick runs on central difference: about a
twentieth of the stick's own distance from the RC frame of examples/rc-frame.toml (0.39,
benchmarks/RESULTS.md)."""


def probe_shape(period: float) -> GroundMotions:
    """``[1, T]`` the unit probe pulse (m/s^2 per unit scale) of a structure of first
    ``period`` (s)."""
    dt = min(0.01, period / PROBE_SAMPLES_PER_PERIOD)
    t = np.arange(int(round(12.0 * period / dt)) + 1) * dt
    shape = np.sin(2.0 * np.pi * t / period) * np.exp(-(((t - 4.0 * period) / (1.5 * period)) ** 2))
    return GroundMotions(shape[None], dt)


def roof_drift_ratio(stick, motions: GroundMotions, height: float) -> np.ndarray:
    """``[n]`` the stick's peak roof displacement over the building's ``height`` (m); inf
    for a record that collapses it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CphysfnoWarning)
        responses = stick.simulate(motions)
    peak = np.abs(responses.displacement[:, :, -1]).max(axis=1) / height
    return np.where(np.isfinite(peak), peak, np.inf)


def scales_reaching(
    stick: Structure, records: GroundMotions, targets: np.ndarray, height: float
) -> np.ndarray:
    """``[n]`` the factor on each of the ``n`` records under which ``stick`` reaches the
    roof drift ratio of ``targets`` (``[n]``; roof over ``height``, m): bisection in the
    factor's logarithm between 1e-3 and 1e3, every record at once."""
    low = np.full(records.n_records, np.log(1e-3))
    high = np.full(records.n_records, np.log(1e3))
    for _ in range(SCALE_HALVINGS):
        middle = 0.5 * (low + high)
        scaled = GroundMotions(np.exp(middle)[:, None] * records.acceleration, records.dt)
        below = roof_drift_ratio(stick, scaled, height) < np.asarray(targets)
        low, high = np.where(below, middle, low), np.where(below, high, middle)
    return np.exp(0.5 * (low + high))


def probe_motions(calibration: StickCalibration, amplitudes: Sequence[float]) -> GroundMotions:
    """``[len(amplitudes), T]`` the probe pulse scaled, for each roof drift ratio of
    ``amplitudes``, so that the stick of ``calibration`` reaches it
    (:func:`scales_reaching`)."""
    unit = probe_shape(float(calibration.periods[0]))
    pulses = GroundMotions(np.repeat(unit.acceleration, len(amplitudes), axis=0), unit.dt)
    height = float(calibration.backbone.heights.sum())
    scales = scales_reaching(calibration.building(), pulses, np.asarray(amplitudes), height)
    return GroundMotions(scales[:, None] * pulses.acceleration, unit.dt)


def pooled_relative_l2(z: np.ndarray, u: np.ndarray) -> float:
    """The relative L2 of ``z`` against ``u`` over all their entries together (inf where
    it is not finite: a collapsed stick's NaN)."""
    error = float(np.sqrt(np.sum((z - u) ** 2) / np.sum(u**2)))
    return error if np.isfinite(error) else float("inf")


def dynamic_errors(
    structure: Structure,
    calibrations: Sequence[StickCalibration],
    floors: np.ndarray,
    amplitudes: Sequence[float],
) -> list[dict[str, float]] | None:
    """For each calibration, law name -> the relative L2 (over probes, samples and
    outputs) of the stick of each fitted law against the structure under the probes of
    :func:`probe_motions` (scaled with the first calibration); None where the structure
    collapses or fails on every probe (a :class:`~cphysfno_core.CphysfnoWarning` says so).

    Args:
        structure: the structure the sticks were fitted to.
        calibrations: its calibrations (one per form of the stick), every candidate law
            fitted in each.
        floors: ``[n_outputs]`` the stick floor of each output.
        amplitudes: the roof drift ratios the probes drive the first calibration's stick to.
    """
    motions = probe_motions(calibrations[0], amplitudes)
    truth = structure.simulate(motions)
    kept = ~truth.collapsed & np.isfinite(truth.displacement).all(axis=(1, 2))
    if not kept.any():
        warnings.warn(
            f"stick of structure '{structure.name}': the structure collapsed or failed on "
            "every probe pulse; the law stays the one the pushovers chose",
            CphysfnoWarning,
            stacklevel=3,
        )
        return None
    probes = motions[np.flatnonzero(kept)]
    u = truth.displacement[kept]
    found = []
    for calibration in calibrations:
        errors = {}
        for law in calibration.fits:
            stick = calibration.building(law)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", CphysfnoWarning)
                z = stick.simulate(probes).displacement[:, :, floors]
            errors[law] = pooled_relative_l2(z, u)
        found.append(errors)
    return found


def integrator_error(calibration: StickCalibration, amplitudes: Sequence[float]) -> float:
    """The relative L2 (over probes, samples and floors) of the stick of ``calibration``
    on ``central-difference`` against the same stick on ``runge-kutta`` under the probe
    pulses of :func:`probe_motions` (inf where a probe collapses one of them and not the
    other). No call into the structure."""
    motions = probe_motions(calibration, amplitudes)
    runs = []
    for integrator in ("runge-kutta", "central-difference"):
        stick = replace(calibration, integrator=integrator).building()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CphysfnoWarning)
            runs.append(stick.simulate(motions).displacement)
    reference, central = runs
    finite = np.isfinite(reference)
    if not np.array_equal(finite, np.isfinite(central)):
        return float("inf")
    return pooled_relative_l2(central[finite], reference[finite])
