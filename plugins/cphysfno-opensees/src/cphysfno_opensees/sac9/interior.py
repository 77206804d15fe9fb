"""The elastic interior sections of the SAC frame's members (fibre model with
``elastic_interior``): where they are, and the stresses of the outermost fibres of the
fibre sections they stand for, which must stay below yield for them to be exact."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from .model import Frame, FrameConfig, fibre_layout
from .sections import WideFlange


@dataclass(frozen=True)
class InteriorSections:
    """The elastic sections inside the members of a model with an elastic interior.

    Attributes:
        sections: ``(element, integration point)`` of each.
        area, inertia: ``[m]`` their area (m^2) and second moment (m^4).
        depth: ``[m]`` the distance of the outermost fibre of the fibre section they stand
            for from its centroid, m.
        yield_stress: ``[m]`` the yield stress of their steel, Pa.
    """

    sections: tuple[tuple[int, int], ...]
    area: np.ndarray
    inertia: np.ndarray
    depth: np.ndarray
    yield_stress: np.ndarray

    @classmethod
    def of(cls, frame: Frame, config: FrameConfig) -> InteriorSections:
        """The interior sections of the model ``frame`` (built from ``config``); none
        unless the fibre model has an elastic interior."""
        members = sorted(frame.members.items())
        if config.model != "fibre" or not config.elastic_interior:
            members = []
        interior = range(2, config.integration_points)
        sections = [(element, point) for element, _ in members for point in interior]
        per_member = [
            (m.shape.area, m.shape.inertia, _outermost(m.shape, config), m.yield_stress)
            for _, m in members
        ]
        columns = np.repeat(np.asarray(per_member, dtype=float).reshape(-1, 4), len(interior), 0)
        return cls(tuple(sections), *columns.T)

    def stresses(self, ops: Any) -> np.ndarray:
        """``[2 m]`` the stresses now of the two outermost fibres of each section (of the
        fibre section it stands for), Pa."""
        forces = np.array(
            [
                ops.eleResponse(element, "section", point, "force")
                for element, point in self.sections
            ]
        ).reshape(-1, 2)
        return self.fibre_stresses(forces)

    def fibre_stresses(self, forces: np.ndarray) -> np.ndarray:
        """``[2 m]`` outermost-fibre stresses (Pa) of axial forces and moments ``[m, 2]``
        (N, N m): ``N / A -+ M y / I`` for each section."""
        axial = forces[:, 0] / self.area
        bending = forces[:, 1] * self.depth / self.inertia
        return np.stack([axial - bending, axial + bending], axis=1).ravel()

    def past_yield(self, ops: Any, share: float) -> bool:
        """Whether an outermost fibre's stress is at ``share`` of its yield stress now."""
        return bool(np.any(np.abs(self.stresses(ops)) >= share * np.repeat(self.yield_stress, 2)))


@functools.lru_cache(maxsize=256)
def _outermost(shape: WideFlange, config: FrameConfig) -> float:
    return max(abs(y) for y, _ in fibre_layout(shape, config))
