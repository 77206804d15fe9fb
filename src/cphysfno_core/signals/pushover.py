"""Static pushovers story by story: the drift protocols that drive them, the lateral load
pattern they push with, and the shear-drift curve of every story they return."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from .errors import InputError
from .linear_system import LinearSystem

ELASTIC_PROBE = 1e-4
"""First step of :func:`monotonic_protocol`, as a fraction of its target: small enough
that the secant slope of every story over it is its initial stiffness."""


@dataclass(frozen=True)
class StoryPushover:
    """Each story's shear-drift curve from one static pushover, point 0 being the state
    before the lateral load (at rest under gravity, where the structure has gravity).

    Attributes:
        roof_drift_ratio: ``[p]`` the protocol the roof followed: roof displacement over
            the building's height (the sum of ``heights``) at each point.
        story_drift: ``[p, d]`` drift of each story (top minus bottom), m.
        story_shear: ``[p, d]`` shear of each story, N.
        masses: ``[d]`` floor masses, kg, bottom floor first (the floor at the top of each
            story).
        heights: ``[d]`` story heights, m.
        pattern: ``[d]`` the shape of the lateral load on the floors, summing to 1.
        stopped: why the analysis ended before the protocol did (its points are then
            fewer than the protocol's), empty if it did not.
    """

    roof_drift_ratio: np.ndarray
    story_drift: np.ndarray
    story_shear: np.ndarray
    masses: np.ndarray
    heights: np.ndarray
    pattern: np.ndarray
    stopped: str = ""

    def __post_init__(self) -> None:
        arrays = ("roof_drift_ratio", "story_drift", "story_shear", "masses", "heights", "pattern")
        for name in arrays:
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=np.float64))
        d, p = self.heights.shape[0], self.roof_drift_ratio.shape[0]
        expected = {
            "roof_drift_ratio": (p,),
            "story_drift": (p, d),
            "story_shear": (p, d),
            "masses": (d,),
            "heights": (d,),
            "pattern": (d,),
        }
        for name, shape in expected.items():
            if getattr(self, name).shape != shape:
                raise InputError(
                    f"StoryPushover.{name} must be {list(shape)} for {p} points and {d} "
                    f"stories, got {list(getattr(self, name).shape)}"
                )
        if p < 2:
            raise InputError("StoryPushover needs at least two points")

    @property
    def n_stories(self) -> int:
        return self.heights.shape[0]

    @property
    def initial_stiffness(self) -> np.ndarray:
        """``[d]`` secant slope of each story's shear over its drift at point 1, N/m (its
        initial stiffness when the first step stays elastic, as in
        :func:`monotonic_protocol`)."""
        return self.story_shear[1] / self.story_drift[1]

    def to_dict(self) -> dict[str, Any]:
        """The curves as plain JSON-compatible values (SI units)."""
        return {
            "units": {"drift": "m", "shear": "N", "mass": "kg", "height": "m"},
            "roof_drift_ratio": self.roof_drift_ratio.tolist(),
            "story_drift": self.story_drift.tolist(),
            "story_shear": self.story_shear.tolist(),
            "masses": self.masses.tolist(),
            "heights": self.heights.tolist(),
            "pattern": self.pattern.tolist(),
            "stopped": self.stopped,
        }

    @classmethod
    def from_dict(cls, document: dict[str, Any]) -> StoryPushover:
        """The curves :meth:`to_dict` wrote."""
        fields = ("roof_drift_ratio", "story_drift", "story_shear", "masses", "heights")
        arrays = {name: np.asarray(document[name], dtype=np.float64) for name in fields}
        return cls(**arrays, pattern=np.asarray(document["pattern"]), stopped=document["stopped"])


def monotonic_protocol(target: float, n_points: int = 101) -> np.ndarray:
    """``[n_points]`` roof drift ratios from 0 to ``target``: a first step of
    :data:`ELASTIC_PROBE` times the target, then equal steps.

    Raises:
        InputError: ``target`` is not a finite number > 0 or ``n_points < 3``.
    """
    if not (np.isfinite(target) and target > 0.0) or n_points < 3:
        raise InputError(
            f"a monotonic protocol needs a target > 0 and n_points >= 3, got {target} and "
            f"{n_points}"
        )
    return np.concatenate([[0.0], target * np.linspace(ELASTIC_PROBE, 1.0, n_points - 1)])


def cyclic_protocol(amplitudes: Sequence[float], points_per_cycle: int = 80) -> np.ndarray:
    """Roof drift ratios of one full cycle at each amplitude in turn: 0 to ``+a``, to
    ``-a``, back to 0, linear between, ``points_per_cycle`` steps a cycle.

    Returns:
        ``[len(amplitudes) * points_per_cycle + 1]`` roof drift ratios, starting at 0.

    Raises:
        InputError: no amplitude, one not finite and > 0, or ``points_per_cycle`` not a
            multiple of 4 of at least 4.
    """
    amplitudes = np.asarray(amplitudes, dtype=np.float64)
    if amplitudes.ndim != 1 or amplitudes.size == 0 or not np.all(np.isfinite(amplitudes)):
        raise InputError(f"a cyclic protocol needs amplitudes > 0, got {amplitudes}")
    if np.any(amplitudes <= 0.0) or points_per_cycle < 4 or points_per_cycle % 4:
        raise InputError(
            f"a cyclic protocol needs amplitudes > 0 and points_per_cycle a multiple of 4, "
            f"got {amplitudes.tolist()} and {points_per_cycle}"
        )
    quarter = points_per_cycle // 4
    up = np.linspace(0.0, 1.0, quarter + 1)[1:]
    shape = np.concatenate([up, 1.0 - 2.0 * np.linspace(0.0, 1.0, 2 * quarter + 1)[1:], up - 1.0])
    return np.concatenate([[0.0], *(a * shape for a in amplitudes)])


def first_mode_pattern(
    system: LinearSystem, floors: Sequence[int], masses: np.ndarray
) -> np.ndarray:
    """``[d]`` the lateral load shape of a pushover: the first elastic mode's displacement
    of each floor times the floor's mass, summing to 1.

    Args:
        system: the structure's linear system (its first mode of ``(K, M)``).
        floors: ``[d]`` the output of each floor, in the rows of ``system.output_map``.
        masses: ``[d]`` floor masses, kg.

    Raises:
        InputError: the mode moves the floors in both directions or not at all (no single
            lateral pattern pushes with it).
    """
    _, vectors = scipy.linalg.eigh(system.stiffness, system.mass, subset_by_index=(0, 0))
    shape = system.output_map[list(floors)] @ vectors[:, 0]
    shape = shape * np.sign(shape[np.argmax(np.abs(shape))])
    load = np.asarray(masses, dtype=np.float64) * shape
    if np.any(load < -1e-9 * np.abs(load).max()) or not load.sum() > 0.0:
        raise InputError(
            f"the first mode moves the floors {shape.tolist()}: give the lateral load "
            "pattern explicitly"
        )
    return np.clip(load, 0.0, None) / np.clip(load, 0.0, None).sum()


def floor_masses(system: LinearSystem, floors: Sequence[int]) -> np.ndarray:
    """``[d]`` floor masses, kg: the inertia of a uniform unit ground acceleration,
    ``M r``, condensed statically onto the floors.

    With ``u = T y`` the displacements of least elastic energy that give the floors
    ``y = L_f u`` (``T = K^-1 L_f^T (L_f K^-1 L_f^T)^-1``, ``L_f`` the floors' rows of the
    output map), the floor masses are ``T^T M r``: a floor's own mass, the masses tied to
    it, and a share of the masses between floors. For a shear building they are its masses.

    Args:
        system: the structure's linear system.
        floors: ``[d]`` the output of each floor, in the rows of ``system.output_map``.
    """
    flexibility, stiffness = _condensation(system, floors)
    shapes = flexibility @ stiffness
    return shapes.T @ system.mass @ system.influence


def floor_stiffness(system: LinearSystem, floors: Sequence[int]) -> np.ndarray:
    """``[d, d]`` the stiffness of the structure at its floors, N/m: ``(L_f K^-1 L_f^T)^-1``,
    the static condensation onto the floors' displacements (the other degrees of freedom
    at least elastic energy, as :func:`floor_masses` takes them), symmetric.

    Args:
        system: the structure's linear system.
        floors: ``[d]`` the output of each floor, in the rows of ``system.output_map``.
    """
    _, stiffness = _condensation(system, floors)
    return 0.5 * (stiffness + stiffness.T)


def _condensation(system: LinearSystem, floors: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """``(K^-1 L_f^T [n_dof, d], (L_f K^-1 L_f^T)^-1 [d, d])``: the static condensation
    onto the floors (``L_f`` the floors' rows of the output map)."""
    rows = system.output_map[list(floors)]
    flexibility = np.linalg.solve(system.stiffness, rows.T)
    return flexibility, np.linalg.inv(rows @ flexibility)


def coupling_story_shear(coupling: np.ndarray, drift: np.ndarray) -> np.ndarray:
    """``[..., d]`` the story shears (N) a linear stiffness between the floors carries: the
    floor forces ``K_c u`` (``coupling [d, d]`` in N/m, ``u`` the floors' displacements,
    the running sum of the story ``drift [..., d]``, m) summed over each story's floors
    above."""
    coupling = np.asarray(coupling, dtype=np.float64)
    below = np.tril(np.ones_like(coupling))  # [i, j] = 1 where floor j is at or below i
    return np.asarray(drift, dtype=np.float64) @ (below.T @ coupling @ below)


def lateral_pattern(pattern: Sequence[float] | np.ndarray, n_floors: int) -> np.ndarray:
    """``[n_floors]`` a lateral load shape scaled to sum to 1.

    Raises:
        InputError: ``pattern`` is not ``n_floors`` finite values >= 0 of positive sum.
    """
    values = np.asarray(pattern, dtype=np.float64)
    if (
        values.shape != (n_floors,)
        or not np.isfinite(values).all()
        or (values < 0).any()
        or not values.sum() > 0
    ):
        raise InputError(
            f"a lateral load pattern needs {n_floors} values >= 0 (one per floor, bottom up) "
            f"of positive sum, got {values.tolist()}"
        )
    return values / values.sum()
