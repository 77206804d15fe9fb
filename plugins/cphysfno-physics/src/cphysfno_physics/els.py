"""Equivalent linear system (ELS): the structure's elastic model, solved exactly (paper §3.2.1)."""

from __future__ import annotations

import dataclasses

import numpy as np
from pydantic import Field

import cphysfno_core
from cphysfno_core import GroundMotions, PhysicsPreprocessor, Structure

from .fitted import check_fitted
from .linear_response import linear_response


class EquivalentLinear(PhysicsPreprocessor):
    """``z`` solves ``M z'' + C z' + s K z = -M r a_g`` from rest (``K``: elastic stiffness).

    ``M``, ``C``, ``K``, ``r`` and the output map ``L`` come from the structure's
    ``linear_system``; with ``s = 1`` (the default) ``K_eq`` is the initial elastic stiffness,
    as in the paper. The response is exact for ground accelerations linear between samples.

    Fitted attributes:
        system_: the linear system with its stiffness scaled by ``stiffness_scale``.
    """

    name = "els"
    requires = frozenset({"equivalent_linear_system"})

    class Params(cphysfno_core.Params):
        stiffness_scale: float = Field(
            1.0, gt=0.0, description="factor s on the elastic stiffness: K_eq = s K"
        )

    def fit(self, structure: Structure) -> EquivalentLinear:
        """Take M, C and s K from the structure's equivalent linear system (its
        ``linear_system`` where it has one)."""
        self.check(structure)
        system = structure.equivalent_linear_system()
        scale = self.params.stiffness_scale
        self.system_ = dataclasses.replace(system, stiffness=scale * system.stiffness)
        return self

    def transform(self, motions: GroundMotions) -> np.ndarray:
        """``[n_records, n_steps, n_outputs]`` ELS displacements in m on the motion's grid."""
        check_fitted(self, "system_")
        return linear_response(self.system_, motions.acceleration, motions.dt)
