"""Which outputs of a structure bound each of its stories, and how tall each story is: what
engineering demand parameters (story drift, floor acceleration) are computed from."""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .errors import InputError


@dataclass(frozen=True)
class Stories:
    """The stories of a structure, in terms of its outputs.

    Story ``s`` spans from output ``lower[s]`` (``None``: the ground, which does not move
    relative to itself) up to output ``upper[s]``, over a height of ``heights_m[s]`` m; its
    drift is ``u[..., upper[s]] - u[..., lower[s]]`` (m) and its drift ratio that over
    ``heights_m[s]``. Output indices count from 0 along the last axis of the structure's
    responses (the order of ``output_names``).

    A shear building or a frame with floor displacements bottom-up is :meth:`stacked`; a
    bridge whose outputs are pier tops has one "story" per pier, from the ground to its top
    (``lower`` all ``None``).

    A story may have no height (``nan``): one of ``zeroLength`` springs, or an isolator,
    whose ends stand at one elevation. Its drift is known, its drift ratio is not
    (:attr:`has_heights`).

    Attributes:
        lower: ``[n_stories]`` output index of each story's bottom, or ``None`` for the
            ground.
        upper: ``[n_stories]`` output index of each story's top.
        heights_m: ``[n_stories]`` story heights in m, each finite and > 0, or ``nan`` for
            a story without height.

    Raises:
        InputError: the three have different lengths, none is given, an index is negative
            or not an integer, a story's top is its bottom, or a height is neither a finite
            number > 0 nor ``nan``.
    """

    lower: tuple[int | None, ...]
    upper: tuple[int, ...]
    heights_m: tuple[float, ...]

    def __post_init__(self) -> None:
        lower = tuple(None if i is None else _index(i, "lower") for i in self.lower)
        upper = tuple(_index(i, "upper") for i in self.upper)
        heights = tuple(_height(h) for h in self.heights_m)
        if not upper:
            raise InputError("Stories needs at least one story")
        if not len(lower) == len(upper) == len(heights):
            raise InputError(
                f"Stories: lower ({len(lower)}), upper ({len(upper)}) and heights_m "
                f"({len(heights)}) must have one entry per story"
            )
        same = [s for s, (b, t) in enumerate(zip(lower, upper, strict=True)) if b == t]
        if same:
            raise InputError(f"Stories: story {same[0]} has output {upper[same[0]]} as both ends")
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)
        object.__setattr__(self, "heights_m", heights)

    @classmethod
    def stacked(cls, heights_m: Sequence[float], first: int = 0) -> Stories:
        """Stories one above the other, floors bottom-up: story ``s`` spans from output
        ``first + s - 1`` (the ground for ``s = 0``) to output ``first + s``.

        Args:
            heights_m: ``[n_stories]`` story heights in m, bottom story first.
            first: output index of the first floor above the ground.
        """
        n = len(heights_m)
        lower = (None, *range(first, first + n - 1))
        return cls(lower, tuple(range(first, first + n)), tuple(heights_m))

    @property
    def n_stories(self) -> int:
        return len(self.upper)

    @property
    def is_stacked(self) -> bool:
        """Whether the stories stand one above the other: the first on the ground, each
        next one on the top of the one below (as :meth:`stacked` makes them)."""
        return self.lower == (None, *self.upper[:-1])

    @property
    def floors(self) -> tuple[int, ...]:
        """The outputs that bound a story (its top or bottom), in increasing index: the
        "floors" whose accelerations are floor accelerations."""
        ends = set(self.upper) | {i for i in self.lower if i is not None}
        return tuple(sorted(ends))

    @property
    def has_heights(self) -> bool:
        """Whether every story has a height (and so a drift ratio)."""
        return not any(math.isnan(h) for h in self.heights_m)

    def without_height(self) -> tuple[str, ...]:
        """The names of the stories that have no height."""
        return tuple(n for n, h in zip(self.names, self.heights_m, strict=True) if math.isnan(h))

    @property
    def names(self) -> tuple[str, ...]:
        """``story-1`` ... ``story-n``, in the order of the stories."""
        return tuple(f"story-{s + 1}" for s in range(self.n_stories))

    def drifts(self, u: np.ndarray) -> np.ndarray:
        """``[n, T, n_stories]`` story drifts in m of displacements ``u [n, T, n_outputs]``
        (m, relative to the ground)."""
        u = np.asarray(u, dtype=np.float64)
        top = u[:, :, list(self.upper)]
        bottom = np.stack(
            [np.zeros(u.shape[:2]) if i is None else u[:, :, i] for i in self.lower], axis=2
        )
        return top - bottom

    def first_past(self, u: np.ndarray, drift_ratio: float) -> np.ndarray:
        """``[n]`` the first sample at which a story's drift ratio exceeds ``drift_ratio``
        in each record of ``u [n, T, n_outputs]`` (m), or -1 where none does (stories
        without height never do)."""
        ratio = np.abs(self.drifts(u)) / np.asarray(self.heights_m)
        past = np.any(np.nan_to_num(ratio, nan=0.0) > drift_ratio, axis=2)
        return np.where(past.any(axis=1), np.argmax(past, axis=1), -1)

    def check_outputs(self, n_outputs: int) -> None:
        """Raise :class:`InputError` unless every index names one of ``n_outputs`` outputs."""
        outside = sorted({i for i in self.floors if i >= n_outputs})
        if outside:
            raise InputError(
                f"Stories name outputs {outside}, but there are {n_outputs} outputs "
                f"(indices 0 to {n_outputs - 1})"
            )


def _index(value: object, what: str) -> int:
    try:
        index = operator.index(value)  # type: ignore[arg-type]
    except TypeError:
        index = None
    if index is None or isinstance(value, bool):
        raise InputError(f"Stories.{what}: output indices must be integers, got {value!r}")
    if index < 0:
        raise InputError(f"Stories.{what}: output indices must be >= 0, got {index}")
    return index


def _height(value: object) -> float:
    try:
        height = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(f"Stories.heights_m: heights are numbers of m, got {value!r}") from None
    if math.isnan(height):
        return height
    if not math.isfinite(height) or height <= 0.0:
        raise InputError(
            f"Stories.heights_m: heights must be finite and > 0 m (or nan: no height), got "
            f"{value!r}"
        )
    return height
