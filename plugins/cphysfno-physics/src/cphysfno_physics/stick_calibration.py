"""Story laws fitted to a structure's pushover: the calibration of the ``stick`` preprocessor.

Each candidate law (a registered story law with a yield drift: ``bilinear``,
``peak-oriented``, ``bouc-wen``, ``pinching``) is fitted to every story's monotonic and
cyclic shear-drift curves together by least squares on the story shear, replaying the
story's drift histories through the law's compiled functions (the story test of a
``shear-building``, ``ShearBuilding.story_shears``, the kernel family that then simulates
the stick). The monotonic curve goes further than the cycles (by default to 3 % of roof
drift against 2 %), so a story that softens there (P-Delta, capping) is seen; ``bilinear``
and ``bouc-wen`` can follow it with a negative post-yield ratio. The law whose worst story
fits best is chosen.

Story springs alone make a shear building, whose higher periods are longer than a frame's
(a frame's beams and columns bend: its floors are coupled beyond the stories next to each
other). The stick can take the structure's own elastic stiffness at its floors instead
(:func:`~cphysfno_core.signals.floor_stiffness`): a linear ``coupling`` between the floors,
the floor stiffness less the springs' initial one, beside springs fitted to the pushovers'
story shears less the share the coupling carries along them. Its periods are then the
floor-condensed structure's and its pushover is still the structure's.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse

from cphysfno_core import ConfigError, CphysfnoError, CphysfnoWarning, create
from cphysfno_core.plugin import LinearSystem, Rayleigh, StoryPushover, Structure
from cphysfno_core.signals import coupling_story_shear, floor_stiffness

MAX_ITERATIONS = 50
"""Least-squares iterations from each start (the Jacobian's evaluations aside)."""

SPRINGS_ALONE = " (springs alone)"
"""What follows a law's name in :attr:`StickCalibration.dynamic_errors` for the stick
without a coupling, where both forms were fitted."""

HELD = 1e-9
"""Half-width of the bounds that hold a parameter at a value in a least-squares fit (which
needs a lower bound below the upper one)."""

UNFINISHED_RESIDUAL = 1e3
"""The largest residual (in peak story shears) of a point, and that of a point where a
law's story test did not stay finite (a sharp Bouc-Wen corner at a tiny yield drift
overflows): far worse than any fit, so that the least squares move away from it and a
start that ends there loses."""

POST_YIELD_SHARE = 0.2
"""Last fraction of the monotonic curve whose slope starts the post-yield stiffness."""

HARDENING = (0.0, 0.99)
"""The post-yield stiffness ratios ``alpha`` the fit can reach for a law whose backbone
does not fall past yield."""

COUPLING_ROUND_OFF = 1e-3
"""A coupling no larger than this share of the floor stiffness's largest entry is none: a
shear building's own floor stiffness is its springs' (to the pushover's initial slopes,
about 1e-4 off for a smooth law), and so small a coupling moves no period by more than
about that share."""


class IndefiniteFloorStiffness(CphysfnoError):
    """The structure's stiffness at its floors is not positive definite: no coupling can
    be made from it."""


SOFTENING = (-0.5, 0.99)
"""The post-yield stiffness ratios ``alpha`` the fit can reach for a law that may soften
past yield (``bilinear`` and ``bouc-wen``, whose ``alpha`` goes down to -0.5)."""


@dataclass(frozen=True)
class LawSpace:
    """How a story law's parameters are fitted: per story the vector ``x`` (the
    post-yield ratio ``alpha``, the yield drift over its first guess, and the law's own
    shape parameters), its bounds and starts, and the law's parameters from it.

    Attributes:
        name: the story law's registry name.
        alpha_bounds: ``(lower, upper)`` of ``alpha``: :data:`SOFTENING` where the law
            takes a negative one, else :data:`HARDENING`.
        shape_starts: starting values of the shape parameters (one tuple per start).
        shape_bounds: ``(lower, upper)`` of each shape parameter.
        shape_names: the law's parameter each shape parameter is, or None where it is
            not one itself (Bouc-Wen's share of ``beta`` and ``gamma``).
        parameters: ``parameters(alpha, u_y, shape) -> dict`` of the law's ``Params``
            fields for one story (``u_y`` in m).
        unnamed_shape: ``unnamed_shape(parameters) -> [d]`` the value of the shape
            parameter that is not one of the law's own (the one ``shape_names`` leaves
            None), from the law's parameters (``[d]`` arrays by name); None where every
            shape parameter is the law's own.
        whole_shapes: indices of the shape parameters the law evaluates faster where
            they are whole numbers (Bouc-Wen's exponent: by multiplication instead of a
            power); :func:`fit_law` rounds them where the fit ties.
    """

    name: str
    alpha_bounds: tuple[float, float] = HARDENING
    shape_starts: tuple[tuple[float, ...], ...] = ((),)
    shape_bounds: tuple[tuple[float, float], ...] = ()
    shape_names: tuple[str | None, ...] = ()
    parameters: Callable[[float, float, Sequence[float]], dict[str, float]] = field(
        default=lambda alpha, u_y, shape: {"alpha": alpha, "yield_displacement": u_y}
    )
    unnamed_shape: Callable[[Mapping[str, np.ndarray]], np.ndarray] | None = None
    whole_shapes: tuple[int, ...] = ()

    def shape_of(self, parameters: Mapping[str, Sequence[float]]) -> np.ndarray:
        """``[d, n_shape]`` each story's shape parameters from the law's parameters (one
        value per story of each): the inverse of :attr:`parameters` for the shape."""
        arrays = {key: np.asarray(value, dtype=np.float64) for key, value in parameters.items()}
        columns = [
            arrays[name] if name else self.unnamed_shape(arrays) for name in self.shape_names
        ]
        d = arrays["yield_displacement"].size
        return np.column_stack(columns) if columns else np.empty((d, 0))

    def story_parameters(
        self, alpha: np.ndarray, u_y: np.ndarray, shapes: np.ndarray
    ) -> dict[str, list[float]]:
        """The law's parameters, one value per story of each, from ``[d]`` ``alpha``,
        ``[d]`` ``u_y`` (m) and ``[d, n_shape]`` shapes: :attr:`parameters` story by
        story (the inverse of :meth:`shape_of` for the shape)."""
        per_story = [
            self.parameters(float(a), float(y), shape)
            for a, y, shape in zip(alpha, u_y, shapes, strict=True)
        ]
        return {key: [float(story[key]) for story in per_story] for key in per_story[0]}

    def held_within_fit(self, story_law: dict[str, Any]) -> dict[str, Any]:
        """``story_law`` (a ``shear-building``'s, one value per story of each parameter)
        with each parameter the fit bounds held within those bounds: a calibration
        interpolated between fitted sticks stays a law the fit could have made."""
        bounds = {"alpha": self.alpha_bounds}
        bounds.update(
            (name, b) for name, b in zip(self.shape_names, self.shape_bounds, strict=True) if name
        )
        held = dict(story_law)
        for name, (low, high) in bounds.items():
            if name in held:
                held[name] = tuple(np.clip(np.asarray(held[name], dtype=np.float64), low, high))
        return held


def _bouc_wen(alpha: float, u_y: float, shape: Sequence[float]) -> dict[str, float]:
    """``A = 1``, exponent ``n``, ``beta + gamma = 1 / u_y^n`` shared as ``(s, 1 - s)``: the
    hysteretic part saturates at ``u_y`` and ``s`` sets the unloading shape."""
    exponent, share = shape
    scale = u_y**-exponent
    return {
        "alpha": alpha,
        "exponent": exponent,
        "yield_displacement": u_y,
        "beta": share * scale,
        "gamma": (1.0 - share) * scale,
    }


def _pinching(alpha: float, u_y: float, shape: Sequence[float]) -> dict[str, float]:
    """The pinch point's drift and force ratios and the unloading stiffness's exponent."""
    pinch_x, pinch_y, beta_unload = shape
    return {
        "alpha": alpha,
        "yield_displacement": u_y,
        "pinch_x": pinch_x,
        "pinch_y": pinch_y,
        "beta_unload": beta_unload,
    }


def _cracked_pinching(alpha: float, u_y: float, shape: Sequence[float]) -> dict[str, float]:
    """:func:`_pinching`'s, the share of the initial stiffness lost at cracking, the
    cracking drift as a share of ``u_y`` and the cracking spring's plastic share."""
    *pinching, crack_share, crack_ratio, crack_hysteresis = shape
    return {
        **_pinching(alpha, u_y, pinching),
        "crack_share": crack_share,
        "crack_displacement": crack_ratio * u_y,
        "crack_hysteresis": crack_hysteresis,
    }


LAW_SPACES = {
    "bilinear": LawSpace("bilinear", SOFTENING),
    "peak-oriented": LawSpace("peak-oriented"),
    "bouc-wen": LawSpace(
        "bouc-wen",
        SOFTENING,
        shape_starts=((1.5, 0.5), (4.0, 0.5), (10.0, 0.5)),
        shape_bounds=((1.0, 20.0), (0.02, 0.98)),
        shape_names=("exponent", None),
        parameters=_bouc_wen,
        unnamed_shape=lambda p: p["beta"] / (p["beta"] + p["gamma"]),
        whole_shapes=(0,),
    ),
    "pinching": LawSpace(
        "pinching",
        shape_starts=((0.5, 0.3, 0.3), (0.9, 0.8, 0.0)),
        shape_bounds=((0.05, 1.0), (0.05, 1.0), (0.0, 1.0)),
        shape_names=("pinch_x", "pinch_y", "beta_unload"),
        parameters=_pinching,
    ),
    "cracked-pinching": LawSpace(
        "cracked-pinching",
        shape_starts=((0.5, 0.3, 0.3, 0.3, 0.2, 0.0), (0.9, 0.8, 0.0, 0.5, 0.1, 1.0)),
        shape_bounds=(
            (0.05, 1.0),
            (0.05, 1.0),
            (0.0, 1.0),
            (0.0, 0.9),
            (0.02, 0.9),
            (0.0, 1.0),
        ),
        shape_names=(
            "pinch_x",
            "pinch_y",
            "beta_unload",
            "crack_share",
            None,
            "crack_hysteresis",
        ),
        parameters=_cracked_pinching,
        unnamed_shape=lambda p: p["crack_displacement"] / p["yield_displacement"],
    ),
}
"""The laws the calibration can fit, by name."""


TIE = (0.01, 1e-3)
"""``(relative, absolute)``: errors of two laws closer than ``relative`` times the lower
plus ``absolute`` (a fit error over the peak shear, a relative L2 under the probes) are a
tie, which the law listed first (the simpler one) takes."""


def first_within_tie(errors: Mapping[Any, float]) -> Any:
    """The first key of ``errors`` (in order) whose error ties with the lowest
    (:data:`TIE`): a law that holds another as a special case (``cracked-pinching`` holds
    ``pinching``) is kept only where it is closer by more than round-off."""
    relative, absolute = TIE
    bound = min(errors.values()) * (1.0 + relative) + absolute
    return next(key for key, error in errors.items() if error <= bound)


@dataclass(frozen=True)
class LawFit:
    """One law fitted to every story.

    Attributes:
        parameters: the law's ``Params`` fields, one value per story (bottom first).
        errors: ``[d]`` each story's fit error, :func:`story_errors` over the points of
            the monotonic and the cyclic curves together: the RMS error of the stick's
            story shear (its spring's and its coupling's) over them divided by the
            story's largest absolute shear on them.
    """

    parameters: dict[str, list[float]]
    errors: list[float]

    @property
    def worst(self) -> float:
        return max(self.errors)


@dataclass(frozen=True)
class StickCalibration:
    """A shear building fitted to a structure: what builds it and how well it fits.

    Attributes:
        backbone: the monotonic pushover (initial stiffnesses, first guesses), which the
            laws are fitted to with the cyclic one.
        cyclic: the cyclic pushover.
        stiffness: ``[d]`` initial story stiffnesses of the stick, N/m: the backbone's
            initial slopes times ``stiffness_scale`` (and each times the refinement's
            factor, where a refinement was kept).
        stiffness_scale: the factor that gives the springs alone the structure's first
            period.
        periods: the structure's first periods, s.
        stick_periods: the stick's periods, s (as many).
        damping_ratio: the structure's damping ratio in its first mode.
        rayleigh_modes: the two modes of the stick's Rayleigh damping, or ``None`` for
            classical damping.
        law: the chosen law's name.
        fits: every candidate law's fit, by name.
        dynamic_errors: law name -> the relative L2 of each law's stick against the
            structure under the probe pulses, where the law was chosen by them
            (``law_choice = "dynamic"``), else None; ``"<law> (springs alone)"`` names the
            stick without a coupling where both forms were fitted.
        coupling: ``[d, d]`` the linear stiffness between the floors beside the springs
            (N/m; the structure's floor stiffness less the springs' initial one), or None
            for springs alone.
        integrator: the ``shear-building`` integrator of the stick.
        integrator_error: the relative L2 of the stick on central difference against
            the same stick on Runge-Kutta under the probe pulses, where the integrator was
            chosen by it, else None.
        refinement: where the stick was refined on synthetic records
            (:func:`~.stick_refinement.refine`): how many were fitted and held out, the
            relative L2 against the structure on each before and after, which refinement
            was taken (``refined``: ``"backbone"``, ``"whole law"``, or None where the
            stick followed the structure already and nothing was searched, with no
            "after" values) and each one's error on the records held out, whether it was
            kept (``accepted``; the stiffnesses and the chosen law's parameters are then
            the refined ones) and the factors found on each story's stiffness and yield
            drift; else None.
    """

    backbone: StoryPushover
    cyclic: StoryPushover
    stiffness: np.ndarray
    stiffness_scale: float
    periods: np.ndarray
    stick_periods: np.ndarray
    damping_ratio: float
    rayleigh_modes: tuple[int, int] | None
    law: str
    fits: dict[str, LawFit]
    dynamic_errors: dict[str, float] | None = None
    coupling: np.ndarray | None = None
    integrator: str = "runge-kutta"
    integrator_error: float | None = None
    refinement: dict[str, Any] | None = None

    def story_law(self) -> dict[str, Any]:
        """The chosen law as a ``shear-building``'s ``story_law``: its name and one value
        per story of each parameter."""
        values = self.fits[self.law].parameters
        return {"name": self.law, **{key: tuple(value) for key, value in values.items()}}

    def shear_building(self) -> dict[str, Any]:
        """The parameters of the ``shear-building`` that is the stick."""
        return {
            "masses": tuple(self.backbone.masses.tolist()),
            "stiffnesses": tuple(self.stiffness.tolist()),
            "story_heights": tuple(self.backbone.heights.tolist()),
            "story_law": self.story_law(),
            "damping_ratio": self.damping_ratio,
            "rayleigh_modes": self.rayleigh_modes,
            "coupling": None
            if self.coupling is None
            else tuple(tuple(row) for row in self.coupling.tolist()),
            "integrator": self.integrator,
        }

    def building(self, law: str | None = None) -> Structure:
        """The stick: the ``shear-building`` of :meth:`shear_building`, with the fitted
        ``law`` (a name in :attr:`fits`) instead of the chosen one where given."""
        member = self if law is None else replace(self, law=law)
        return create("structure", "shear-building", **member.shear_building())

    def stick_shears(self, curve: StoryPushover, law: str | None = None) -> np.ndarray:
        """``[p, d]`` the stick's story shears (N) along the story drifts of ``curve``
        (from rest): its springs' and its coupling's; with the fitted ``law`` instead of
        the chosen one where given."""
        member = self if law is None else replace(self, law=law)
        shears = replay(member.story_law(), curve, self.stiffness)
        if self.coupling is not None:
            shears += coupling_story_shear(self.coupling, curve.story_drift)
        return shears

    def stick_errors(self, law: str) -> list[float]:
        """``[d]`` :func:`story_errors` of the stick with the fitted ``law`` (its springs'
        and its coupling's shears) against the structure's, over the monotonic and the
        cyclic curves together."""
        curves = (self.backbone, self.cyclic)
        shears = np.vstack([self.stick_shears(curve, law) for curve in curves])
        return story_errors(shears, np.vstack([c.story_shear for c in curves])).tolist()

    def to_dict(self) -> dict[str, Any]:
        """Everything as plain JSON-compatible values (SI units)."""
        return {
            "backbone": self.backbone.to_dict(),
            "cyclic": self.cyclic.to_dict(),
            "stiffness": self.stiffness.tolist(),
            "stiffness_scale": self.stiffness_scale,
            "periods": self.periods.tolist(),
            "stick_periods": self.stick_periods.tolist(),
            "damping_ratio": self.damping_ratio,
            "rayleigh_modes": None if self.rayleigh_modes is None else list(self.rayleigh_modes),
            "law": self.law,
            "fits": {
                name: {"parameters": fit.parameters, "errors": fit.errors}
                for name, fit in self.fits.items()
            },
            "dynamic_errors": self.dynamic_errors,
            "coupling": None if self.coupling is None else self.coupling.tolist(),
            "integrator": self.integrator,
            "integrator_error": self.integrator_error,
            "refinement": self.refinement,
        }

    @classmethod
    def from_dict(cls, document: dict[str, Any]) -> StickCalibration:
        """The calibration :meth:`to_dict` wrote."""
        modes = document["rayleigh_modes"]
        return cls(
            backbone=StoryPushover.from_dict(document["backbone"]),
            cyclic=StoryPushover.from_dict(document["cyclic"]),
            stiffness=np.asarray(document["stiffness"], dtype=np.float64),
            stiffness_scale=float(document["stiffness_scale"]),
            periods=np.asarray(document["periods"], dtype=np.float64),
            stick_periods=np.asarray(document["stick_periods"], dtype=np.float64),
            damping_ratio=float(document["damping_ratio"]),
            rayleigh_modes=None if modes is None else (int(modes[0]), int(modes[1])),
            law=document["law"],
            fits={
                name: LawFit(fit["parameters"], fit["errors"])
                for name, fit in document["fits"].items()
            },
            dynamic_errors=document.get("dynamic_errors"),
            coupling=None
            if document.get("coupling") is None
            else np.asarray(document["coupling"], dtype=np.float64),
            integrator=document.get("integrator", "runge-kutta"),
            integrator_error=document.get("integrator_error"),
            refinement=document.get("refinement"),
        )


def chain_stiffness(stiffness: np.ndarray) -> np.ndarray:
    """``[d, d]`` the stiffness matrix (N/m) of a chain of story springs of ``stiffness``
    (N/m, bottom first) at its floors."""
    k = np.asarray(stiffness, dtype=np.float64)
    above = np.append(k[1:], 0.0)
    return np.diag(k + above) - np.diag(k[1:], 1) - np.diag(k[1:], -1)


def chain_periods(
    masses: np.ndarray, stiffness: np.ndarray, coupling: np.ndarray | None = None
) -> np.ndarray:
    """``[d]`` periods (s, longest first) of the shear building of floor ``masses`` (kg)
    and story ``stiffness`` (N/m), with a ``coupling`` (``[d, d]``, N/m) between its floors
    where given."""
    matrix = chain_stiffness(stiffness)
    if coupling is not None:
        matrix = matrix + coupling
    root = 1.0 / np.sqrt(np.asarray(masses, dtype=np.float64))
    squares = np.linalg.eigvalsh(matrix * np.outer(root, root))
    return 2.0 * np.pi / np.sqrt(squares)


def first_guess(
    backbone: StoryPushover, stiffness: np.ndarray, lowest: float
) -> tuple[np.ndarray, np.ndarray]:
    """``([d] alpha, [d] u_y in m)``: the bilinear curve of each story's initial stiffness
    (N/m) through the end of its monotonic curve, with the slope of the curve's last
    :data:`POST_YIELD_SHARE` after yield (its ratio to the initial stiffness held in
    ``[lowest, 0.9]``: a falling curve gives a negative ``alpha`` where ``lowest`` is)."""
    drift, shear = backbone.story_drift, backbone.story_shear
    p = drift.shape[0]
    start = min(int((1.0 - POST_YIELD_SHARE) * (p - 1)), p - 2)
    slope = (shear[-1] - shear[start]) / (drift[-1] - drift[start])
    alpha = np.clip(slope / stiffness, lowest, 0.9)
    end = drift[-1]
    u_y = (shear[-1] - alpha * stiffness * end) / (stiffness * (1.0 - alpha))
    return alpha, np.clip(u_y, 1e-3 * end, end)


def fit_law(
    space: LawSpace,
    curves: Sequence[StoryPushover],
    stiffness: np.ndarray,
    guess: tuple[np.ndarray, np.ndarray],
) -> LawFit:
    """Least squares on the story shears over the points of every curve together, every
    story at once (a story's parameters touch its own shears only), each story's residuals
    divided by its largest absolute shear on the curves, from each of the law's starts;
    the best start per story is kept. Where the law has :attr:`LawSpace.whole_shapes`,
    they are then rounded to whole numbers, the rest fitted again, and each story keeps
    the rounded fit where its error ties with the free one (:func:`first_within_tie`):
    the same fit, a faster stick.

    Args:
        space: the law and its parameters.
        curves: the pushovers fitted (the monotonic and the cyclic one), each replayed
            from rest.
        stiffness: ``[d]`` the stick's initial story stiffnesses, N/m (held).
        guess: ``([d] alpha, [d] u_y)`` from :func:`first_guess`.
    """
    d = curves[0].n_stories
    alpha0, u_y0 = guess
    reference = np.vstack([curve.story_shear for curve in curves])
    scale = np.abs(reference).max(axis=0)
    scale = np.where(scale > 0.0, scale, 1.0)
    width = 2 + len(space.shape_bounds)

    def story_laws(x: np.ndarray) -> dict[str, Any]:
        rows = x.reshape(d, width)
        parameters = space.story_parameters(rows[:, 0], rows[:, 1] * u_y0, rows[:, 2:])
        return {"name": space.name, **{key: tuple(value) for key, value in parameters.items()}}

    def shears(x: np.ndarray) -> np.ndarray:
        return replay(story_laws(x), curves, stiffness)

    def residual(x: np.ndarray) -> np.ndarray:
        scaled = np.nan_to_num((shears(x) - reference) / scale, nan=UNFINISHED_RESIDUAL)
        return np.clip(scaled, -UNFINISHED_RESIDUAL, UNFINISHED_RESIDUAL).ravel()

    lower = np.tile([space.alpha_bounds[0], 1e-3, *(b[0] for b in space.shape_bounds)], d)
    upper = np.tile([space.alpha_bounds[1], 1e3, *(b[1] for b in space.shape_bounds)], d)
    points = reference.shape[0]
    sparsity = scipy.sparse.kron(scipy.sparse.identity(d), np.ones((points, width)))
    # rows are ordered [point, story]: reorder the block-diagonal pattern to match
    order = np.arange(d * points).reshape(d, -1).T.ravel()
    sparsity = sparsity.tocsr()[order]

    def fitted(x0: np.ndarray, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        result = scipy.optimize.least_squares(
            residual,
            np.clip(x0, low, high),
            bounds=(low, high),
            jac_sparsity=sparsity,
            x_scale="jac",
            xtol=1e-12,
            ftol=1e-12,
            gtol=1e-12,
            max_nfev=MAX_ITERATIONS,
        )
        error = np.nan_to_num(story_errors(shears(result.x), reference), nan=np.inf)
        return result.x.reshape(d, width), error

    best_x, best_error = None, np.full(d, np.inf)
    for shape in space.shape_starts:
        x0 = np.column_stack([alpha0, np.ones(d), np.tile(shape, (d, 1))]).ravel()
        x, error = fitted(x0, lower, upper)
        if best_x is None:
            best_x = x.copy()
        better = error < best_error
        best_x[better] = x[better]
        best_error = np.minimum(error, best_error)
    if space.whole_shapes:
        columns = [2 + index for index in space.whole_shapes]
        low, high = lower.reshape(d, width).copy(), upper.reshape(d, width).copy()
        whole = np.clip(np.round(best_x[:, columns]), low[:, columns], high[:, columns])
        # a held interval around the whole value, within the bounds
        low[:, columns] = np.clip(whole - HELD, low[:, columns], high[:, columns] - 2.0 * HELD)
        high[:, columns] = low[:, columns] + 2.0 * HELD
        x = best_x.copy()
        x[:, columns] = whole
        x, _ = fitted(x.ravel(), low.ravel(), high.ravel())
        x[:, columns] = whole
        error = np.nan_to_num(story_errors(shears(x.ravel()), reference), nan=np.inf)
        ties = [
            first_within_tie({"whole": e, "free": b}) == "whole"
            for e, b in zip(error, best_error, strict=True)
        ]
        best_x[ties], best_error[ties] = x[ties], error[ties]
    laws = story_laws(best_x.ravel())
    parameters = {key: list(value) for key, value in laws.items() if key != "name"}
    return LawFit(parameters, best_error.tolist())


def replay(
    story_law: dict[str, Any],
    curves: StoryPushover | Sequence[StoryPushover],
    stiffness: np.ndarray,
) -> np.ndarray:
    """``[p, d]`` story shears (N) of a shear building of ``stiffness`` (N/m) and
    ``story_law`` driven along the story drifts of ``curves``: one pushover, or several,
    each from rest, their points one after the other."""
    several = (curves,) if isinstance(curves, StoryPushover) else tuple(curves)
    building = create(
        "structure",
        "shear-building",
        masses=tuple(several[0].masses.tolist()),
        stiffnesses=tuple(np.asarray(stiffness, dtype=np.float64).tolist()),
        story_heights=tuple(several[0].heights.tolist()),
        story_law=story_law,
    )
    return np.vstack([building.story_shears(curve.story_drift) for curve in several])


def story_errors(shear: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``[d]`` RMS of ``shear - reference`` over the points, over the largest absolute
    ``reference`` shear, per story (each ``[p, d]``, N; the fit's errors are over the
    points of the monotonic and the cyclic curves one after the other)."""
    rms = np.sqrt(np.mean((shear - reference) ** 2, axis=0))
    peak = np.abs(reference).max(axis=0)
    return rms / np.where(peak > 0.0, peak, 1.0)


def fit_laws(
    backbone: StoryPushover, cyclic: StoryPushover, stiffness: np.ndarray, laws: Sequence[str]
) -> tuple[str, dict[str, LawFit]]:
    """Fit every law in ``laws`` (names in :data:`LAW_SPACES`) and choose one.

    Each law is fitted to the monotonic and the cyclic curves together (:func:`fit_law`)
    from its own :func:`first_guess`. The chosen law has the lowest worst-story error
    (:attr:`LawFit.worst`: RMS shear error over the points of both curves over the
    story's peak shear on them); a tie (:data:`TIE`) goes to the law listed first.

    Returns:
        ``(chosen law's name, every fit by name)``.

    Raises:
        ConfigError: a name is not one the calibration can fit.
    """
    unknown = [name for name in laws if name not in LAW_SPACES]
    if unknown or not laws:
        raise ConfigError(
            f"stick.laws: the calibration fits {', '.join(LAW_SPACES)}; got {list(laws)}"
        )
    fits: dict[str, LawFit] = {}
    for name in laws:
        space = LAW_SPACES[name]
        guess = first_guess(backbone, stiffness, space.alpha_bounds[0])
        fits[name] = fit_law(space, (backbone, cyclic), stiffness, guess)
    chosen = first_within_tie({name: fits[name].worst for name in laws})
    return chosen, fits


def modal_damping(system: LinearSystem, n_modes: int) -> np.ndarray:
    """``[min(n_modes, n_dof)]`` the damping ratios of the first undamped modes of
    ``system``: ``phi_j^T C phi_j / (2 omega_j)`` with ``phi_j`` mass-normalised."""
    count = min(n_modes, system.n_dof)
    squares, vectors = scipy.linalg.eigh(
        system.stiffness, system.mass, subset_by_index=(0, count - 1)
    )
    return np.einsum("ij,ik,kj->j", vectors, system.damping, vectors) / (2.0 * np.sqrt(squares))


def stick_damping(ratios: np.ndarray) -> tuple[float, tuple[int, int] | None]:
    """``(damping_ratio, rayleigh_modes)`` of a stick for a structure of modal damping
    ``ratios``: classical at the first mode's ratio where all are the first's (relative
    1e-6), else Rayleigh at that ratio in the first mode and the mode whose ratio is
    closest to the first's (the second mode a Rayleigh-damped structure is matched at)."""
    first = float(ratios[0])
    if len(ratios) == 1 or np.allclose(ratios, first, rtol=1e-6, atol=1e-12):
        return first, None
    return first, (1, 2 + int(np.argmin(np.abs(ratios[1:] - first))))


def calibrate(
    structure: Structure,
    backbone: StoryPushover,
    cyclic: StoryPushover,
    laws: Sequence[str],
    coupled: bool = True,
) -> StickCalibration:
    """The stick of ``structure`` from its monotonic and cyclic pushovers.

    - Masses, heights: the pushover's floors.
    - Initial story stiffnesses: the backbone's initial slopes, all scaled by one factor
      so that the first period of the springs alone is the structure's
      (``structure.periods``) to round-off.
    - Coupling (where ``coupled``): :func:`floor_coupling`, the structure's floor
      stiffness less the springs'; the stick's periods are then those of the floor
      stiffness.
    - Damping: :func:`stick_damping` of the modal damping ratios of the structure's
      equivalent linear system.
    - Story law: :func:`fit_laws` on the monotonic and cyclic curves less the shear the
      coupling carries along them, at those stiffnesses.
    """
    count = min(backbone.n_stories, len(structure.periods()))
    periods = np.asarray(structure.periods(count), dtype=np.float64)
    initial = backbone.initial_stiffness
    if not np.all(initial > 0.0):
        raise CphysfnoError(
            f"stick: the pushover of structure '{structure.name}' gives story initial slopes "
            f"{initial.tolist()} N/m; every story needs a positive one"
        )
    scale = float((chain_periods(backbone.masses, initial)[0] / periods[0]) ** 2)
    stiffness = scale * initial
    coupling = floor_coupling(structure, stiffness) if coupled else None
    stick_periods = chain_periods(backbone.masses, stiffness, coupling)[:count]
    ratio, modes = stick_damping(modal_damping(structure.equivalent_linear_system(), count))
    springs = [_less_coupling(curve, coupling) for curve in (backbone, cyclic)]
    law, fits = fit_laws(*springs, stiffness, laws)
    calibration = StickCalibration(
        backbone,
        cyclic,
        stiffness,
        scale,
        periods,
        stick_periods,
        ratio,
        modes,
        law,
        fits,
        coupling=coupling,
    )
    if coupling is None:
        return calibration
    # the errors of the stick, not of its springs' share
    fits = {
        name: LawFit(fit.parameters, calibration.stick_errors(name)) for name, fit in fits.items()
    }
    law = first_within_tie({name: fits[name].worst for name in laws})
    return replace(calibration, fits=fits, law=law)


def floor_coupling(structure: Structure, stiffness: np.ndarray) -> np.ndarray | None:
    """``[d, d]`` the linear stiffness (N/m) between the floors that gives story springs
    of initial ``stiffness`` (N/m) the structure's own stiffness at its floors
    (:func:`~cphysfno_core.signals.floor_stiffness` of its ``linear_system``, else of its
    ``equivalent_linear_system``); None where the springs have it already (a shear
    building's: within :data:`COUPLING_ROUND_OFF`).

    Raises:
        IndefiniteFloorStiffness: the floor stiffness is not positive definite (a
            structure unstable under its gravity loads at rest).
    """
    system = (
        structure.linear_system()
        if "linear_system" in structure.capabilities
        else structure.equivalent_linear_system()
    )
    floors = floor_stiffness(system, structure.stories().upper)
    if np.linalg.eigvalsh(floors)[0] <= 0.0:
        raise IndefiniteFloorStiffness(
            f"stick: the stiffness of structure '{structure.name}' at its floors is not "
            'positive definite; set coupling = "none" for story springs alone'
        )
    coupling = floors - chain_stiffness(stiffness)
    if np.abs(coupling).max() <= COUPLING_ROUND_OFF * np.abs(floors).max():
        return None
    return coupling


def _less_coupling(curve: StoryPushover, coupling: np.ndarray | None) -> StoryPushover:
    """``curve`` with the story shears the springs carry: less the coupling's share."""
    if coupling is None:
        return curve
    share = coupling_story_shear(coupling, curve.story_drift)
    return replace(curve, story_shear=curve.story_shear - share)


def warn_where_off(structure: Structure, calibration: StickCalibration, tolerance: float) -> None:
    """Warn (:class:`~cphysfno_core.CphysfnoWarning`) naming the modes whose period or
    damping ratio in the stick of ``calibration`` is more than ``tolerance`` (relative)
    from the structure's (a damping that is neither classical nor Rayleigh, such as
    mass-proportional damping alone, gives other ratios)."""
    periods, stick_periods = calibration.periods, calibration.stick_periods
    _warn_where_off(structure, "periods", stick_periods, periods, tolerance)
    ratios = modal_damping(structure.equivalent_linear_system(), len(periods))
    omega = 2.0 * np.pi / stick_periods
    modes = calibration.rayleigh_modes
    if modes is None:
        stick_ratios = np.full(len(periods), calibration.damping_ratio)
    else:
        rayleigh = Rayleigh.matching(
            omega[modes[0] - 1], omega[modes[1] - 1], calibration.damping_ratio
        )
        stick_ratios = rayleigh.ratio(omega)
    _warn_where_off(structure, "damping ratios", stick_ratios, ratios, tolerance)


def _warn_where_off(
    structure: Structure, what: str, stick: np.ndarray, own: np.ndarray, tolerance: float
) -> None:
    """Warn (:class:`~cphysfno_core.CphysfnoWarning`) naming the modes where ``stick``
    differs from the structure's ``own`` by more than ``tolerance`` (relative)."""
    off = np.abs(stick - own) > tolerance * np.abs(own)
    if off.any():
        warnings.warn(
            f"stick of structure '{structure.name}': {what} {stick.tolist()} against the "
            f"structure's {own.tolist()}; modes {(np.flatnonzero(off) + 1).tolist()} differ by "
            f"more than {tolerance:.0%}",
            CphysfnoWarning,
            stacklevel=4,
        )
