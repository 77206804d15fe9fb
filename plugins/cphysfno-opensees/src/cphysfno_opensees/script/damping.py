"""The damping of a user's model: Rayleigh on the initial or the committed stiffness,
optionally over a region of it only, or OpenSees' modal damping; the same commands in the
probe (whose linear equations carry the damping matrix) and in every record's analysis."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.linalg
from pydantic import BaseModel, ConfigDict, Field, model_validator

from cphysfno_core.plugin import Rayleigh

from .source import ScriptError

DampingKind = Literal["rayleigh", "rayleigh-committed", "modal"]
"""``rayleigh``: mass and initial stiffness (``alphaM``, ``betaKinit``);
``rayleigh-committed``: mass and the last committed stiffness (``alphaM``, ``betaKcomm``);
``modal``: OpenSees' ``modalDamping`` over the modes of an eigen analysis at the gravity
state."""

REGION_TAG = 2_147_470_000
"""Tags of the damping regions (kept clear of a script's)."""

MODAL_EIGEN_SOLVER = "-fullGenLapack"
"""The eigen solver of modal damping's eigen analysis: it finds every mode that carries
mass (Arpack's default solver cannot find them all)."""


class DampingRegion(BaseModel):
    """The part of the model Rayleigh damping acts on (OpenSees ``region ... -rayleigh``):
    the mass of ``nodes`` and the stiffness (and mass) of ``elements``; the rest is left
    undamped (an isolator's ``zeroLength`` elements and its nodes, say)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    nodes: tuple[int, ...] = Field((), description="nodes whose mass is damped (alphaM)")
    elements: tuple[int, ...] = Field(
        (), description="elements whose stiffness is damped (betaK)"
    )

    @model_validator(mode="after")
    def _not_empty(self) -> DampingRegion:
        if not self.nodes and not self.elements:
            raise ValueError("damping_region: give the nodes or the elements damped")
        return self


@dataclass(frozen=True)
class DampingSetup:
    """The damping commands of the model, picklable for the worker processes.

    Attributes:
        kind: :data:`DampingKind`.
        rayleigh: the Rayleigh factors (``rayleigh`` kinds; zeros for ``modal``).
        modal_ratios: the damping ratio of each mode from 1 (``modal``).
        region: the part of the model Rayleigh damping acts on, or None for the whole.
    """

    kind: DampingKind
    rayleigh: Rayleigh
    modal_ratios: tuple[float, ...] = ()
    region: DampingRegion | None = None

    def apply(self, ops: Any, *, tangent: bool = False) -> None:
        """Set the damping in the domain (after gravity, before the transient).

        Args:
            tangent: put the stiffness-proportional factor on the current tangent
                (``betaK``) instead, which at a committed state is the committed stiffness:
                how the linear equations of ``rayleigh-committed`` are read.
        """
        if self.kind == "modal":
            ops.eigen(MODAL_EIGEN_SOLVER, len(self.modal_ratios))
            ops.modalDamping(*self.modal_ratios)
            return
        factors = [self.rayleigh.mass_factor, 0.0, 0.0, 0.0]
        slot = 1 if tangent else (2 if self.kind == "rayleigh" else 3)
        factors[slot] = self.rayleigh.stiffness_factor
        if self.region is None:
            ops.rayleigh(*factors)
            return
        if self.region.elements:
            ops.region(REGION_TAG, "-eleOnly", *self.region.elements, "-rayleigh", *factors)
        if self.region.nodes:
            masses = (factors[0], 0.0, 0.0, 0.0)
            ops.region(REGION_TAG + 1, "-nodeOnly", *self.region.nodes, "-rayleigh", *masses)

    def describe(self) -> dict[str, Any]:
        """The damping as JSON-ready values (for ``opensees-model.json``)."""
        if self.kind == "modal":
            return {"kind": self.kind, "modal_ratios": list(self.modal_ratios)}
        return {
            "kind": self.kind,
            "mass_factor_per_s": self.rayleigh.mass_factor,
            "stiffness_factor_s": self.rayleigh.stiffness_factor,
            "region": None
            if self.region is None
            else {"nodes": list(self.region.nodes), "elements": list(self.region.elements)},
        }

    def modal_matrix(self, mass: np.ndarray, stiffness: np.ndarray) -> np.ndarray:
        """``[r, r]`` the damping matrix of ``modal``, ``M Φ diag(2 ζ_i ω_i) Φ^T M`` over
        the damped modes (Φ mass-normalised), of the equations ``(M, K)``: what OpenSees'
        modal damping applies, which it does not assemble into a matrix it can print."""
        n = len(self.modal_ratios)
        squares, shapes = scipy.linalg.eigh(stiffness, mass, subset_by_index=(0, n - 1))
        omega = np.sqrt(np.clip(squares, 0.0, None))
        weights = 2.0 * np.asarray(self.modal_ratios) * omega
        projected = mass @ shapes
        return projected @ np.diag(weights) @ projected.T



@dataclass(frozen=True)
class DampingChoice:
    """The damping a user chose, before the model's frequencies are known.

    Attributes:
        kind: :data:`DampingKind`.
        ratio: the damping ratio: in ``modes`` for Rayleigh, in every mode for ``modal``
            unless ``modal_ratios`` gives one per mode.
        modes: the two modes (from 1) Rayleigh damping matches ``ratio`` in.
        modal_ratios: the ratio of each mode from 1 (``modal``), or None.
        region: the part of the model Rayleigh damping acts on, or None for the whole.
    """

    kind: DampingKind
    ratio: float
    modes: tuple[int, int]
    modal_ratios: tuple[float, ...] | None = None
    region: DampingRegion | None = None

    def setup(self, omega: np.ndarray, script: Any) -> DampingSetup:
        """The damping commands for the model whose circular frequencies at the gravity
        state are ``omega`` (rad/s, ascending).

        Raises:
            ScriptError: the modes asked for are more than the model has (DOFs with mass).
        """
        if self.kind == "modal":
            what = f"modal_ratios = {list(self.modal_ratios or ())}"
            needed = len(self.modal_ratios or ())
        else:
            what, needed = f"rayleigh_modes = {list(self.modes)}", max(self.modes)
        if needed > omega.size:
            raise ScriptError(
                f"{what}: the model of OpenSees script {script} has {omega.size} mode(s) "
                "(DOFs with mass)"
            )
        if self.kind == "modal":
            ratios = self.modal_ratios or (self.ratio,) * omega.size
            return DampingSetup(self.kind, Rayleigh(0.0, 0.0), tuple(ratios))
        factors = Rayleigh(0.0, 0.0)
        if self.ratio > 0.0:
            first, second = (omega[m - 1] for m in self.modes)
            factors = Rayleigh.matching(first, second, self.ratio)
        return DampingSetup(self.kind, factors, region=self.region)
