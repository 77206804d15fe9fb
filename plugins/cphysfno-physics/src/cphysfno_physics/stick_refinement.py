"""The stick's backbone refined on the structure's own response to synthetic records.

The pushovers fit each story statically, under one lateral pattern; under a record the
stories of a frame share the drift otherwise (a cracked RC frame's stories soften at
other drifts than its first-mode pushover shows them to). The refinement analyses the
structure on a few synthetic records (``spectrum-compatible`` with its default scenario,
:data:`DURATION` long, seed :data:`SEED`), each scaled so that the pushover-fitted stick
reaches a roof drift ratio between the smallest and the largest of the amplitudes asked,
and fits per story the stick's initial stiffness (a factor within
``exp(+-STIFFNESS_RANGE)``), the law's post-yield ratio ``alpha`` (within its fit bounds)
and its yield drift (a factor within ``exp(+-YIELD_RANGE)``) by least squares on the
floor displacements. The law's shape parameters (pinching, cracking share, Bouc-Wen's
exponent) stay the pushovers'. Every :data:`HELD_OUT_EVERY`-th record is held out: the
refined stick is kept only where the pushover-fitted one is further than
:data:`~.stick_probes.FOLLOWS` from the structure on them and the refined one closer by
more than a tie (:data:`~.stick_calibration.TIE`).
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import scipy.optimize

from cphysfno_core import ConfigError, CphysfnoWarning, GroundMotions, RegistryError, create
from cphysfno_core.plugin import Structure

from .stick_calibration import (
    LAW_SPACES,
    LawFit,
    StickCalibration,
    chain_periods,
    first_within_tie,
)
from .stick_probes import (
    FOLLOWS,
    PROBE_SAMPLES_PER_PERIOD,
    pooled_relative_l2,
    scales_reaching,
)

DURATION = 15.0
"""Length of each synthetic record, s."""

SEED = 0
"""Seed of the synthetic records: a refit of the same structure gives the same stick."""

HELD_OUT_EVERY = 3
"""Every this-th record (the third, the sixth...) is held out of the fit."""

STIFFNESS_RANGE = 0.3
"""Largest ``|ln|`` of the factor on a story's initial stiffness."""

YIELD_RANGE = 0.7
"""Largest ``|ln|`` of the factor on a story's yield drift."""

MAX_EVALUATIONS = 60
"""Least-squares evaluations of the stick (the Jacobian's aside)."""


def refinement_records(
    calibration: StickCalibration, amplitudes: list[float], n: int
) -> GroundMotions:
    """``[n, T]`` the synthetic records, each scaled so that the stick of ``calibration``
    reaches one of ``n`` roof drift ratios spaced geometrically from the smallest to the
    largest of ``amplitudes`` (at ``min(0.01, T1 / 50)`` s a sample).

    Raises:
        ConfigError: the ``spectrum-compatible`` ground motion is not installed.
    """
    period = float(calibration.periods[0])
    try:
        source = create(
            "ground_motion",
            "spectrum-compatible",
            dt=min(0.01, period / PROBE_SAMPLES_PER_PERIOD),
            duration=DURATION,
        )
    except RegistryError as error:
        raise ConfigError(
            "stick.refine_records: the refinement's synthetic records come from the "
            "'spectrum-compatible' ground motion of the cphysfno-ground-motions plugin "
            f"({error}); install it or set refine_records = 0"
        ) from None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CphysfnoWarning)
        records = source.sample(n, np.random.default_rng(SEED))
    targets = np.geomspace(min(amplitudes), max(amplitudes), n)
    height = float(calibration.backbone.heights.sum())
    scales = scales_reaching(calibration.building(), records, targets, height)
    return GroundMotions(scales[:, None] * records.acceleration, records.dt)


def refined_member(calibration: StickCalibration, x: np.ndarray) -> StickCalibration:
    """The calibration with ``x = [ln stiffness factors, alpha, ln yield factors]`` (each
    ``[d]``) applied to its story stiffnesses and its chosen law, and the periods of the
    stick so made; the law's pushover fit errors are left empty (:func:`with_fit_errors`)."""
    d = calibration.stiffness.size
    stiffness = calibration.stiffness * np.exp(x[:d])
    parameters = dict(calibration.fits[calibration.law].parameters)
    parameters["alpha"] = list(x[d : 2 * d])
    parameters = LAW_SPACES[calibration.law].yield_scaled(parameters, np.exp(x[2 * d :]))
    masses, coupling = calibration.backbone.masses, calibration.coupling
    return replace(
        calibration,
        stiffness=stiffness,
        fits={**calibration.fits, calibration.law: LawFit(parameters, [])},
        stick_periods=chain_periods(masses, stiffness, coupling)[: calibration.periods.size],
    )


def with_fit_errors(calibration: StickCalibration) -> StickCalibration:
    """The calibration with its chosen law's pushover fit errors those of its stick."""
    law = calibration.law
    fit = LawFit(calibration.fits[law].parameters, calibration.stick_errors(law))
    return replace(calibration, fits={**calibration.fits, law: fit})


def refine(
    structure: Structure,
    calibration: StickCalibration,
    floors: np.ndarray,
    amplitudes: list[float],
    n_records: int,
) -> StickCalibration:
    """The calibration refined on the structure's response to ``n_records`` synthetic
    records (:func:`refinement_records`), or as it was where the held-out records do not
    favour the refinement or the stick followed the structure within
    :data:`~.stick_probes.FOLLOWS` already; either way with ``refinement`` saying what was
    done (the relative L2 against the structure before and after, on the records fitted
    and the records held out, and the factors found). Where the structure survives too
    few records to fit on some and check on others, nothing is refined and a
    :class:`~cphysfno_core.CphysfnoWarning` says so.

    Args:
        structure: the structure the stick was fitted to.
        calibration: its pushover-fitted stick.
        floors: ``[n_outputs]`` the stick floor of each output.
        amplitudes: the roof drift ratios the records span.
        n_records: how many records.
    """
    motions = refinement_records(calibration, amplitudes, n_records)
    truth = structure.simulate(motions)
    kept = np.flatnonzero(~truth.collapsed & np.isfinite(truth.displacement).all(axis=(1, 2)))
    held = kept[HELD_OUT_EVERY - 1 :: HELD_OUT_EVERY]
    fitted = np.setdiff1d(kept, held)
    if held.size == 0 or fitted.size == 0:
        warnings.warn(
            f"stick of structure '{structure.name}': {kept.size} of {n_records} refinement "
            "records left the structure standing, too few to fit on some and check on the "
            "others; the stick stays the pushovers' fit",
            CphysfnoWarning,
            stacklevel=3,
        )
        return calibration

    def stick_z(x: np.ndarray, rows: np.ndarray) -> np.ndarray:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CphysfnoWarning)
            z = refined_member(calibration, x).building().simulate(motions[rows]).displacement
        z = z[:, :, floors]
        return np.where(np.isfinite(z), z, 0.0)  # a collapsed stick's NaN as zero

    def stick_error(x: np.ndarray, rows: np.ndarray) -> np.ndarray:
        u = truth.displacement[rows]
        return (stick_z(x, rows) - u).ravel() / np.sqrt(np.sum(u**2))

    d = calibration.stiffness.size
    space = LAW_SPACES[calibration.law]
    alpha = np.asarray(calibration.fits[calibration.law].parameters["alpha"], dtype=np.float64)
    lower = np.concatenate(
        [np.full(d, -STIFFNESS_RANGE), np.full(d, space.alpha_bounds[0]), np.full(d, -YIELD_RANGE)]
    )
    upper = np.concatenate(
        [np.full(d, STIFFNESS_RANGE), np.full(d, space.alpha_bounds[1]), np.full(d, YIELD_RANGE)]
    )
    x0 = np.clip(np.concatenate([np.zeros(d), alpha, np.zeros(d)]), lower, upper)
    result = scipy.optimize.least_squares(
        stick_error,
        x0,
        bounds=(lower, upper),
        args=(fitted,),
        diff_step=1e-3,
        x_scale=0.1,
        max_nfev=MAX_EVALUATIONS,
    )
    before = stick_z(x0, kept)  # both subsets in one simulation
    in_fitted = np.isin(kept, fitted)
    u = truth.displacement
    errors = {
        "fitted_before": pooled_relative_l2(before[in_fitted], u[fitted]),
        "fitted_after": float(np.linalg.norm(result.fun)),  # the residual at result.x
        "held_out_before": pooled_relative_l2(before[~in_fitted], u[held]),
        "held_out_after": pooled_relative_l2(stick_z(result.x, held), u[held]),
    }
    choice = {"pushover": errors["held_out_before"], "refined": errors["held_out_after"]}
    accepted = errors["held_out_before"] > FOLLOWS and first_within_tie(choice) == "refined"
    refinement = {
        "records": n_records,
        "fitted": int(fitted.size),
        "held_out": int(held.size),
        **errors,
        "accepted": accepted,
        "stiffness_factors": np.exp(result.x[:d]).tolist(),
        "yield_factors": np.exp(result.x[2 * d :]).tolist(),
    }
    chosen = with_fit_errors(refined_member(calibration, result.x)) if accepted else calibration
    return replace(chosen, refinement=refinement)
