"""Static pushover of an OpenSees building model and the shear building it implies.

:func:`push` pushes a model under any lateral pattern along any roof displacement
protocol, monotonic or cyclic (the ``pushover`` capability of the OpenSees structures).

The paper's equivalent linear system of a frame (§5.3) comes from a pushover with an
inverted triangular load pattern: its initial slope gives the elastic story stiffnesses
``k_i = V_i / delta_i`` (story shear over interstory drift), which make a tridiagonal
shear-building stiffness with the floor masses. :func:`run_pushover` runs the analysis on a
model already defined in OpenSees, :class:`PushoverCurve` holds what it found (saved as
JSON, drawn by :func:`plot_pushover`), and :func:`shear_building` builds the linear system.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cphysfno_core import CphysfnoError, InputError
from cphysfno_core.plugin import LinearSystem, Rayleigh, Stories, StoryPushover
from cphysfno_core.signals import first_mode_pattern, floor_masses, lateral_pattern

ELASTIC_TOLERANCE = 1e-3
"""A point of the curve is elastic while its secant stiffness (base shear over roof
displacement) is within this fraction of the initial slope."""


PATTERN_TAG = 9101
"""Tag of the lateral load's time series and pattern (kept clear of a script's)."""

RETRY_SPLIT = 10
"""Sub-steps a pushover step is cut into when it does not converge whole."""


class PushoverError(CphysfnoError):
    """A pushover that did not run to its target or never left the elastic range."""


@dataclass(frozen=True)
class Pushed:
    """What :func:`push` found, point 0 being the state it started from.

    Attributes:
        floor_displacement: ``[p, n]`` floor displacements from the start, model units.
        load_factor: ``[p]`` factor on the lateral pattern (the base shear for a pattern
            summing to 1), model force units.
        stopped: why it ended before the last target, empty if it did not.
    """

    floor_displacement: np.ndarray
    load_factor: np.ndarray
    stopped: str


def push(
    ops: Any,
    floors: list[int],
    dof: int,
    pattern: np.ndarray,
    roof: np.ndarray,
    strength_loss: float | None = None,
) -> Pushed:
    """Push a model already defined in OpenSees, its analysis already configured
    (constraints, numberer, system, test, algorithm), with a lateral load of shape
    ``pattern`` along ``dof`` on the floor nodes, the roof (the last floor) following
    ``roof`` by displacement control, one step from each target to the next (cut into
    :data:`RETRY_SPLIT` sub-steps where it does not converge whole).

    Args:
        ops: the ``openseespy.opensees`` module.
        floors: node tags of the floors, bottom up.
        dof: the DOF (from 1) along which the floors are pushed.
        pattern: ``[n]`` load on each floor.
        roof: ``[p]`` roof displacements from the start, model units (``roof[0]`` = 0).
        strength_loss: stop after a point that moves the roof past every earlier point in
            its direction with a load (in that direction) below ``1 - strength_loss`` of
            the largest at such points so far; ``None``: never.

    Returns:
        The points reached; the analysis is wiped.
    """
    ops.timeSeries("Linear", PATTERN_TAG)
    ops.pattern("Plain", PATTERN_TAG, PATTERN_TAG)
    for node, share in zip(floors, pattern, strict=True):
        load = [0.0] * int(ops.getNDF(node)[0])
        load[dof - 1] = float(share)
        ops.load(node, *load)
    start = np.array([ops.nodeDisp(node, dof) for node in floors])
    displacement, factor = [np.zeros(len(floors))], [0.0]
    stopped, reach, strongest = "", np.zeros(2), np.zeros(2)
    for step in range(1, len(roof)):
        increment = float(roof[step] - roof[step - 1])
        if not _advance(ops, floors[-1], dof, increment):
            stopped = (
                f"did not converge at step {step} of {len(roof) - 1} (roof displacement "
                f"{roof[step]:.4g} in the model's length unit)"
            )
            break
        displacement.append([ops.nodeDisp(node, dof) for node in floors] - start)
        factor.append(ops.getLoadFactor(PATTERN_TAG))
        side = int(roof[step] < 0.0)
        if abs(roof[step]) >= reach[side]:
            reach[side] = abs(roof[step])
            resisting = factor[-1] * (-1.0 if side else 1.0)
            strongest[side] = max(strongest[side], resisting)
            if strength_loss is not None and resisting < (1.0 - strength_loss) * strongest[side]:
                stopped = (
                    f"lost {strength_loss:.0%} of its strength at step {step} of "
                    f"{len(roof) - 1} (roof displacement {roof[step]:.4g} in the model's "
                    "length unit)"
                )
                break
    ops.wipeAnalysis()
    return Pushed(np.asarray(displacement), np.asarray(factor), stopped)


STRENGTH_LOSS = 0.2
"""A story pushover stops after a point that pushes the roof further than before with less
than ``1 - STRENGTH_LOSS`` of the largest base shear so far."""


def story_pushover_by(
    pusher: Callable[[np.ndarray, np.ndarray], Pushed],
    stories: Stories,
    system: LinearSystem,
    roof_drift_ratio: np.ndarray,
    pattern: np.ndarray | None,
    metres_per_unit: float = 1.0,
) -> StoryPushover:
    """Each story's shear-drift curve of a building pushed by ``pusher(pattern, roof)``
    (which runs :func:`push` on the model at its gravity state, in a worker process).

    Args:
        pusher: pushes the model with the lateral load ``pattern [d]`` (summing to 1) on
            its floors bottom-up, the roof along ``roof [p]`` (model length units).
        stories: the building's stories, one above the other (heights in m).
        system: its linear system at the gravity state (SI lengths).
        roof_drift_ratio: ``[p]`` roof displacement over the building's height, from 0.
        pattern: ``[d]`` lateral load on the floors, bottom up, or ``None`` for the first
            mode of ``system`` times the floor masses.
        metres_per_unit: metres per length unit of the model.

    Returns:
        The curves: story drifts in m, story shears (the lateral loads above each story)
        in the model's force unit, floor masses condensed from ``system``
        (:func:`~cphysfno_core.signals.floor_masses`).

    Raises:
        InputError: ``pattern`` is not one value >= 0 per floor of positive sum.
    """
    masses = floor_masses(system, stories.upper)
    if pattern is None:
        pattern = first_mode_pattern(system, stories.upper, masses)
    pattern = lateral_pattern(pattern, stories.n_stories)
    heights = np.asarray(stories.heights_m)
    ratio = np.asarray(roof_drift_ratio, dtype=np.float64)
    pushed = pusher(pattern, ratio * heights.sum() / metres_per_unit)
    displacement = pushed.floor_displacement * metres_per_unit
    drift = np.diff(displacement, axis=1, prepend=0.0)
    loads = pushed.load_factor[:, None] * pattern[None, :]
    shear = np.cumsum(loads[:, ::-1], axis=1)[:, ::-1]
    reached = ratio[: displacement.shape[0]]
    return StoryPushover(reached, drift, shear, masses, heights, pattern, pushed.stopped)


def _advance(ops: Any, roof_node: int, dof: int, increment: float) -> bool:
    """Move the roof by ``increment`` in one displacement-controlled step, or in
    :data:`RETRY_SPLIT` sub-steps; whether it converged."""
    for parts in (1, RETRY_SPLIT):
        ops.integrator("DisplacementControl", roof_node, dof, increment / parts)
        ops.analysis("Static")
        if all(ops.analyze(1) == 0 for _ in range(parts)):
            return True
    return False


@dataclass(frozen=True)
class PushoverCurve:
    """Result of a displacement-controlled pushover, point 0 being the unloaded state.

    Attributes:
        heights: ``[n]`` floor elevations above the ground, m, bottom floor first.
        masses: ``[n]`` floor masses, kg.
        pattern: ``[n]`` shape of the lateral load (sums to 1).
        floor_displacement: ``[p, n]`` floor displacements relative to the ground, m.
        base_shear: ``[p]`` total lateral load, N.
    """

    heights: np.ndarray
    masses: np.ndarray
    pattern: np.ndarray
    floor_displacement: np.ndarray
    base_shear: np.ndarray

    @property
    def roof_displacement(self) -> np.ndarray:
        """``[p]`` displacement of the top floor, m."""
        return self.floor_displacement[:, -1]

    @property
    def roof_drift_ratio(self) -> np.ndarray:
        """``[p]`` roof displacement over the roof's height."""
        return self.roof_displacement / self.heights[-1]

    @property
    def story_shear(self) -> np.ndarray:
        """``[p, n]`` shear of each story (the loads on the floors above it), N."""
        loads = self.base_shear[:, None] * self.pattern[None, :]
        return np.cumsum(loads[:, ::-1], axis=1)[:, ::-1]

    @property
    def story_drift(self) -> np.ndarray:
        """``[p, n]`` interstory drift of each story (floor minus the floor below), m."""
        below = np.zeros((self.floor_displacement.shape[0], 1))
        return np.diff(np.concatenate([below, self.floor_displacement], axis=1), axis=1)

    @property
    def initial_stiffness(self) -> float:
        """Initial slope of base shear over roof displacement, N/m (first load step)."""
        return float(self.base_shear[1] / self.roof_displacement[1])

    @property
    def story_stiffness(self) -> np.ndarray:
        """``[n]`` elastic story stiffnesses ``k_i = V_i / delta_i`` at the first load step,
        N/m."""
        return self.story_shear[1] / self.story_drift[1]

    @property
    def elastic_points(self) -> int:
        """Number of leading points whose secant stiffness is within
        :data:`ELASTIC_TOLERANCE` of the initial slope (the unloaded point included)."""
        secant = self.base_shear[1:] / self.roof_displacement[1:]
        elastic = np.abs(secant / self.initial_stiffness - 1.0) <= ELASTIC_TOLERANCE
        return 1 + int(np.argmin(elastic)) if not elastic.all() else len(self.base_shear)

    @property
    def peak_base_shear(self) -> float:
        """Largest base shear on the curve, N."""
        return float(self.base_shear.max())

    def to_json(self) -> str:
        """The curve and the stiffnesses derived from it, as a JSON document (SI units)."""
        document = {
            "units": {"length": "m", "force": "N", "mass": "kg", "stiffness": "N/m"},
            "heights": self.heights.tolist(),
            "masses": self.masses.tolist(),
            "pattern": self.pattern.tolist(),
            "floor_displacement": self.floor_displacement.tolist(),
            "base_shear": self.base_shear.tolist(),
            "initial_stiffness": self.initial_stiffness,
            "story_stiffness": self.story_stiffness.tolist(),
            "elastic_points": self.elastic_points,
        }
        return json.dumps(document)

    @classmethod
    def from_json(cls, text: str) -> PushoverCurve:
        """The curve :meth:`to_json` wrote."""
        document = json.loads(text)
        fields = ("heights", "masses", "pattern", "floor_displacement", "base_shear")
        return cls(*(np.asarray(document[name], dtype=np.float64) for name in fields))


def triangular_pattern(heights: np.ndarray) -> np.ndarray:
    """``[n]`` inverted triangular load shape: proportional to the height above the
    ground, summing to 1."""
    heights = np.asarray(heights, dtype=np.float64)
    return heights / heights.sum()


def run_pushover(
    ops: Any,
    floors: list[int],
    heights: np.ndarray,
    masses: np.ndarray,
    *,
    target_drift_ratio: float = 0.03,
    n_steps: int = 300,
    configure: Any = None,
) -> PushoverCurve:
    """Push a model already defined in OpenSees (gravity, if any, applied and held) with
    an inverted triangular load on its floors until the roof reaches
    ``target_drift_ratio`` times its height, in ``n_steps`` equal displacement steps.

    Args:
        ops: the ``openseespy.opensees`` module.
        floors: node tags whose horizontal (DOF 1) displacement is each floor's, bottom up.
        heights: ``[n]`` floor elevations above the ground, m.
        masses: ``[n]`` floor masses, kg (kept with the curve for the shear building).
        target_drift_ratio: roof displacement to reach, over the roof's height.
        n_steps: displacement-control steps.
        configure: ``configure(ops)`` sets constraints, numberer, system, test and
            algorithm; ``None`` uses Transformation, RCM, BandGeneral, NormDispIncr 1e-8
            and Newton.

    Returns:
        The curve, ``n_steps + 1`` points.

    Raises:
        InputError: the floors, heights and masses do not match or the target is not
            positive.
        PushoverError: a step did not converge, or the curve never left the elastic range
            (the target is too small to find the yield).
    """
    heights = np.asarray(heights, dtype=np.float64)
    masses = np.asarray(masses, dtype=np.float64)
    if not (len(floors) == heights.size == masses.size) or heights.ndim != 1:
        raise InputError(
            f"one height and one mass per floor: {len(floors)} floors, {heights.size} "
            f"heights, {masses.size} masses"
        )
    if not target_drift_ratio > 0.0 or n_steps < 2:
        raise InputError(
            f"target_drift_ratio must be > 0 and n_steps >= 2, got {target_drift_ratio} "
            f"and {n_steps}"
        )
    pattern = triangular_pattern(heights)
    if configure is None:
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", 1e-8, 50)
        ops.algorithm("Newton")
    else:
        configure(ops)
    roof = target_drift_ratio * heights[-1] * np.linspace(0.0, 1.0, n_steps + 1)
    pushed = push(ops, floors, 1, pattern, roof)
    if pushed.stopped:
        raise PushoverError(f"the pushover {pushed.stopped}")
    curve = PushoverCurve(heights, masses, pattern, pushed.floor_displacement, pushed.load_factor)
    if curve.elastic_points == len(curve.base_shear):
        raise PushoverError(
            f"the pushover stayed elastic up to a roof drift ratio of {target_drift_ratio} "
            f"(secant stiffness within {ELASTIC_TOLERANCE:g} of the initial slope "
            "everywhere): raise target_drift_ratio to find where the structure yields"
        )
    return curve


def shear_building(
    masses: np.ndarray,
    story_stiffness: np.ndarray,
    damping_ratio: float,
    damping_modes: tuple[int, int] = (1, 3),
) -> LinearSystem:
    """The shear building of ``story_stiffness`` and ``masses``, Rayleigh damped.

    ``K`` is tridiagonal (``K_ii = k_i + k_{i+1}``, ``K_{i,i+1} = -k_{i+1}``), ``M``
    diagonal, ``C = a M + b K`` with ``damping_ratio`` in the two modes of
    ``damping_modes`` (1-based, of ``M`` and ``K``); influence ones, identity output map.

    Args:
        masses: ``[n]`` floor masses, kg.
        story_stiffness: ``[n]`` story stiffnesses, N/m, bottom story first.
        damping_ratio: fraction of critical damping in the two modes.
        damping_modes: the two modes matched.
    """
    masses = np.asarray(masses, dtype=np.float64)
    k = np.asarray(story_stiffness, dtype=np.float64)
    n = masses.size
    if k.shape != (n,) or (k <= 0).any() or (masses <= 0).any():
        raise InputError(
            f"shear building needs {n} positive story stiffnesses and masses, got {k} and {masses}"
        )
    if not (1 <= min(damping_modes) and max(damping_modes) <= n):
        raise InputError(f"damping_modes must lie in 1..{n}, got {damping_modes}")
    above = np.append(k[1:], 0.0)
    stiffness = np.diag(k + above) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    mass = np.diag(masses)
    omega = np.sqrt(np.linalg.eigvalsh(stiffness / np.sqrt(np.outer(masses, masses))))
    first, second = (omega[m - 1] for m in damping_modes)
    damping = Rayleigh.matching(first, second, damping_ratio)
    return LinearSystem(mass, damping.matrix(mass, stiffness), stiffness, np.ones(n), np.eye(n))


def plot_pushover(curve: PushoverCurve, path: str | Path | None = None):
    """Draw the pushover curve with its initial slope (left) and the story stiffnesses
    (right); save it to ``path`` when given.

    Returns:
        The matplotlib figure.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), width_ratios=(3, 2))
    drift = 100.0 * curve.roof_drift_ratio
    left.plot(drift, curve.base_shear / 1e6, color="k", lw=1.2, label="pushover")
    reach = curve.peak_base_shear / curve.initial_stiffness
    line = np.array([0.0, reach])
    left.plot(
        100.0 * line / curve.heights[-1],
        curve.initial_stiffness * line / 1e6,
        color="tab:red",
        ls="--",
        lw=1.0,
        label=f"initial slope {curve.initial_stiffness / 1e6:.1f} MN/m",
    )
    limit = curve.elastic_points - 1
    left.plot(
        drift[limit],
        curve.base_shear[limit] / 1e6,
        "o",
        color="tab:blue",
        label="end of the elastic range",
    )
    left.set_xlabel("roof drift ratio (%)")
    left.set_ylabel("base shear (MN)")
    left.set_title("pushover, inverted triangular load")
    left.legend(fontsize=8, loc="lower right")
    stories = np.arange(1, curve.heights.size + 1)
    right.barh(stories, curve.story_stiffness / 1e6, color="tab:gray")
    right.set_yticks(stories)
    right.set_xlabel("k_i = V_i / delta_i (MN/m)")
    right.set_ylabel("story")
    right.set_title("elastic story stiffness")
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=130)
    return fig
