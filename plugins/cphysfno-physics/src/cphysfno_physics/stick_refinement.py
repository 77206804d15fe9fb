"""The stick refined on the structure's own response to synthetic records.

The pushovers fit each story statically, under one lateral pattern; under a record the
stories of a frame share the drift otherwise (a cracked RC frame's stories soften at
other drifts than its first-mode pushover shows them to), and its loops dissipate
otherwise than the pushovers' cycles show. The refinement analyses the structure on a
few synthetic records (``spectrum-compatible`` with its default scenario,
:data:`DURATION` long, seed :data:`SEED`), each scaled so that the pushover-fitted stick
reaches a roof drift ratio between the smallest and the largest of the amplitudes asked,
and fits the stick to their floor displacements, twice (the second starting where the
first ended), by Powell's derivative-free search on the relative L2 (within bounds, at
most :data:`EVALUATIONS_PER_UNKNOWN` simulations of the stick per unknown; least squares
on finite differences of a hysteretic response stall near their start, where a step
crosses a yield event):

- ``"backbone"``: per story the initial stiffness (a factor within
  ``exp(+-STIFFNESS_RANGE)``), the law's post-yield ratio ``alpha`` (within its fit
  bounds) and its yield drift (a factor within ``exp(+-YIELD_RANGE)``), the law's shape
  (pinching, cracking, Bouc-Wen's exponent and unloading share) the pushovers';
- ``"whole law"``: the shape parameters too (within their fit bounds), but a law's whole
  ones (Bouc-Wen's exponent where the pushovers rounded it), for laws that have a shape.

Every :data:`HELD_OUT_EVERY`-th record is held out. Where the pushover-fitted stick is
within :data:`~.stick_probes.FOLLOWS` of the structure on them, nothing is searched.
Else of the two refinements the one closer to the structure on them is taken (the
backbone one where they tie, :data:`~.stick_calibration.TIE`), and it is kept only where
it is closer than the pushover-fitted stick by more than a tie.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
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

EVALUATIONS_PER_UNKNOWN = 30
"""Simulations of the stick on the records fitted that each refinement may take, per
unknown it fits."""

TOLERANCES = {"xtol": 1e-3, "ftol": 1e-4}
"""When Powell's search stops: a step in the unknowns (factors' logarithms, ratios) and
a relative change of the squared error below these."""

POLISH_EVALUATIONS = 30
"""Least-squares evaluations of the stick after Powell's search (the Jacobian's aside)."""


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


def story_rows(calibration: StickCalibration) -> np.ndarray:
    """``[d, 3 + n_shape]`` the refinement's unknowns of each story for the stick as it
    is: ``[ln stiffness factor (0), alpha, ln yield factor (0), shape...]``."""
    parameters = calibration.fits[calibration.law].parameters
    alpha = np.asarray(parameters["alpha"], dtype=np.float64)
    zeros = np.zeros_like(alpha)
    shape = LAW_SPACES[calibration.law].shape_of(parameters)
    return np.column_stack([zeros, alpha, zeros, shape])


def refined_member(calibration: StickCalibration, rows: np.ndarray) -> StickCalibration:
    """The calibration with ``rows`` (:func:`story_rows`'s layout) applied to its story
    stiffnesses and its chosen law, and the periods of the stick so made; the law's
    pushover fit errors are left empty (:func:`with_fit_errors`)."""
    stiffness = calibration.stiffness * np.exp(rows[:, 0])
    space = LAW_SPACES[calibration.law]
    parameters = calibration.fits[calibration.law].parameters
    u_y = np.asarray(parameters["yield_displacement"], dtype=np.float64) * np.exp(rows[:, 2])
    new = space.story_parameters(rows[:, 1], u_y, rows[:, 3:])
    masses, coupling = calibration.backbone.masses, calibration.coupling
    return replace(
        calibration,
        stiffness=stiffness,
        fits={**calibration.fits, calibration.law: LawFit({**parameters, **new}, [])},
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
    :data:`~.stick_probes.FOLLOWS` on them already (then nothing is searched,
    ``refined`` is None); either way with ``refinement`` saying what was done (the
    relative L2 against the structure before and after, on the records fitted and the
    records held out, each refinement's on those held out, which refinement was taken,
    and its factors). Where the structure survives too few records to fit on some
    and check on others, nothing is refined and a :class:`~cphysfno_core.CphysfnoWarning`
    says so.

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

    def stick_z(rows: np.ndarray, subset: np.ndarray) -> np.ndarray:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CphysfnoWarning)
            member = refined_member(calibration, rows).building()
            z = member.simulate(motions[subset]).displacement[:, :, floors]
        return np.where(np.isfinite(z), z, 0.0)  # a collapsed stick's NaN as zero

    def stick_error(x: np.ndarray, free: np.ndarray, base: np.ndarray) -> np.ndarray:
        """The stick's error on the records fitted, ``x`` for ``base[free]``, over the
        norm of their displacements (its norm is the relative L2)."""
        rows = base.copy()
        rows[free] = x
        u = truth.displacement[fitted]
        return (stick_z(rows, fitted) - u).ravel() / np.sqrt(np.sum(u**2))

    start = story_rows(calibration)
    before = stick_z(start, kept)  # both subsets in one simulation
    in_fitted = np.isin(kept, fitted)
    u = truth.displacement
    checked = {
        "records": n_records,
        "fitted": int(fitted.size),
        "held_out": int(held.size),
        "fitted_before": pooled_relative_l2(before[in_fitted], u[fitted]),
        "held_out_before": pooled_relative_l2(before[~in_fitted], u[held]),
    }
    if checked["held_out_before"] <= FOLLOWS:  # nothing to refine
        return replace(calibration, refinement={**checked, "accepted": False, "refined": None})
    lower, upper = _bounds(calibration)
    found, fitted_after = {}, {}
    base = start
    for name, free in _free_unknowns(calibration).items():
        result = _searched(stick_error, base[free], lower[free], upper[free], (free, base))
        fitted_after[name] = float(np.linalg.norm(result.fun))  # the residual at result.x
        base = base.copy()
        base[free] = result.x
        found[name] = base
    held_out_after = {
        name: pooled_relative_l2(stick_z(rows, held), u[held]) for name, rows in found.items()
    }
    refined = first_within_tie(held_out_after)
    choice = {"pushover": checked["held_out_before"], "refined": held_out_after[refined]}
    accepted = first_within_tie(choice) == "refined"
    rows = found[refined]
    refinement = {
        **checked,
        "fitted_after": fitted_after[refined],
        "held_out_after": held_out_after[refined],
        "refined": refined,
        "held_out_by_refinement": held_out_after,
        "accepted": accepted,
        "stiffness_factors": np.exp(rows[:, 0]).tolist(),
        "yield_factors": np.exp(rows[:, 2]).tolist(),
    }
    chosen = with_fit_errors(refined_member(calibration, rows)) if accepted else calibration
    return replace(chosen, refinement=refinement)


def _searched(
    error: Callable[..., np.ndarray],
    x0: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    args: tuple,
) -> scipy.optimize.OptimizeResult:
    """Where within bounds ``|error(x, *args)|`` is least (``x``, and ``fun`` the error
    there): Powell's search from ``x0`` (:data:`EVALUATIONS_PER_UNKNOWN`,
    :data:`TOLERANCES`), then least squares on finite differences from where it ended
    (:data:`POLISH_EVALUATIONS`), which close in fast where the response is smooth in
    ``x`` and keep Powell's end where not."""
    start = np.clip(x0, lower, upper)
    powell = scipy.optimize.minimize(
        lambda x: float(np.sum(error(x, *args) ** 2)),
        start,
        method="Powell",
        bounds=scipy.optimize.Bounds(lower, upper),
        options={"maxfev": EVALUATIONS_PER_UNKNOWN * start.size, **TOLERANCES},
    )
    return scipy.optimize.least_squares(
        error,
        np.clip(powell.x, lower, upper),
        bounds=(lower, upper),
        args=args,
        diff_step=1e-3,
        x_scale=0.1,
        max_nfev=POLISH_EVALUATIONS,
    )


def _bounds(calibration: StickCalibration) -> tuple[np.ndarray, np.ndarray]:
    """``([d, 3 + n_shape] lower, upper)`` bounds of :func:`story_rows`'s unknowns."""
    space = LAW_SPACES[calibration.law]
    d = calibration.stiffness.size
    low = [
        -STIFFNESS_RANGE,
        space.alpha_bounds[0],
        -YIELD_RANGE,
        *(b[0] for b in space.shape_bounds),
    ]
    high = [
        STIFFNESS_RANGE,
        space.alpha_bounds[1],
        YIELD_RANGE,
        *(b[1] for b in space.shape_bounds),
    ]
    return np.tile(low, (d, 1)), np.tile(high, (d, 1))


def _free_unknowns(calibration: StickCalibration) -> dict[str, np.ndarray]:
    """``{refinement: [d, 3 + n_shape] mask}`` the unknowns each refinement fits, in order
    (each starts where the one before ended): ``"backbone"`` the stiffness, ``alpha`` and
    the yield drift; ``"whole law"`` the shape parameters too, but the law's whole ones
    (:attr:`~.stick_calibration.LawSpace.whole_shapes`), where it has any others."""
    space = LAW_SPACES[calibration.law]
    d, width = calibration.stiffness.size, 3 + len(space.shape_bounds)
    backbone = np.zeros((d, width), dtype=bool)
    backbone[:, :3] = True
    whole = np.ones((d, width), dtype=bool)
    whole[:, [3 + index for index in space.whole_shapes]] = False
    if np.array_equal(whole, backbone):
        return {"backbone": backbone}
    return {"backbone": backbone, "whole law": whole}
