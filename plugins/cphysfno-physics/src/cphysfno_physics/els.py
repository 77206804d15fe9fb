"""Equivalent linear system (ELS): the structure's elastic model, solved exactly (paper §3.2.1)."""

from __future__ import annotations

import dataclasses
from typing import Literal

import numpy as np
import scipy.linalg
from pydantic import Field

from cphysfno_core import ConfigError, GroundMotions, edp, plugin
from cphysfno_core.plugin import LinearSystem, PhysicsPreprocessor, Structure
from cphysfno_core.signals import monotonic_protocol

from .fitted import check_fitted
from .linear_response import linear_response


class EquivalentLinear(PhysicsPreprocessor):
    """``z`` solves ``M z'' + C z' + s K z = -M r a_g`` from rest (``K``: elastic stiffness).

    ``M``, ``C``, ``K``, ``r`` and the output map ``L`` come from the structure's
    ``linear_system``; with ``s = 1`` (the default) ``K_eq`` is the initial elastic stiffness,
    as in the paper. The response is exact for ground accelerations linear between samples.

    With ``stiffness = "secant"`` each record gets its own effective stiffness, as isolation
    design takes an effective stiffness at the design displacement (equivalent
    linearisation): :meth:`fit` pushes the structure (capability ``pushover``, its first
    mode times its floor masses, to a roof drift ratio of ``target_drift_ratio``) and keeps
    the secant of its base shear against its roof displacement, ``k_sec(D) = V(D) / D``;
    :meth:`transform` solves each record with ``s K``, ``s = k_sec(D) / k_sec(0)`` (times
    ``stiffness_scale``), where ``D`` is the peak roof displacement of that very response,
    found by bisection (``iterations`` halvings, 14 by default: ``s`` to within 1e-4 of
    the initial stiffness). With ``hysteretic_damping`` (the default) the secant system
    also gets Jacobsen's equivalent viscous damping ratio of an elastic-perfectly-plastic
    loop at that secant, ``(2 / pi)(1 - s)``, as stiffness-proportional damping at its first
    mode; the structure's own damping matrix stays. Beyond the pushover's last point the
    last secant holds. Equivalent linearisation aims at peaks; on a single bilinear story
    under white noise it follows the history better than the initial stiffness (relative
    L2 0.75 against 0.93 on 40 records) but its peaks less well (median |ln| 0.38 against
    0.16): measure it on your structure before relying on it.

    Fitted attributes:
        system_: the linear system with its stiffness scaled by ``stiffness_scale``.
        secant_: ``secant`` only: ``(roof displacement [p] m, k_sec / k_sec(0) [p])`` of the
            pushover, increasing in displacement.
        roof_: ``secant`` only: the output that is the roof (the top of the top story).
        omega1_: ``secant`` only: the first circular frequency of ``system_``, rad/s.
    """

    name = "els"
    requires = frozenset({"equivalent_linear_system"})

    class Params(plugin.Params):
        stiffness_scale: float = Field(
            1.0, gt=0.0, description="factor s on the elastic stiffness: K_eq = s K"
        )
        system: Literal["equivalent", "exact"] = Field(
            "equivalent",
            description="'equivalent': the structure's equivalent linear system (its own "
            "linear system unless it defines another, e.g. the paper's pushover shear "
            "building of a frame); 'exact': its own linear system",
        )
        stiffness: Literal["initial", "secant"] = Field(
            "initial",
            description="'initial': K_eq = s K for every record; 'secant': each record's "
            "own secant stiffness from the structure's pushover at its peak roof displacement",
        )
        target_drift_ratio: float = Field(
            0.05, gt=0.0, le=0.2, description="secant: roof drift ratio of the pushover"
        )
        iterations: int = Field(
            14, ge=1, description="secant: halvings of the bracket on each record's stiffness"
        )
        hysteretic_damping: bool = Field(
            True,
            description="secant: add Jacobsen's equivalent viscous damping of an elastic-"
            "perfectly-plastic loop at the secant s, (2/pi)(1 - s), stiffness-proportional "
            "at the first mode of the secant system",
        )

    def fit(self, structure: Structure) -> EquivalentLinear:
        """Take M, C and s K from the structure's equivalent linear system (its
        ``linear_system`` where it has one; with ``system = "exact"`` its
        ``linear_system``); with ``stiffness = "secant"`` also push it.

        Raises:
            CapabilityError: ``secant`` for a structure without ``pushover`` or ``stories``.
            ConfigError: ``secant`` for a structure whose stories do not stand one above
                the other (no roof to read).
        """
        self.check(structure)
        if self.params.system == "exact":
            structure.require("linear_system", "preprocessor 'els' with system = 'exact'")
            system = structure.linear_system()
        else:
            system = structure.equivalent_linear_system()
        scale = self.params.stiffness_scale
        self.system_ = dataclasses.replace(system, stiffness=scale * system.stiffness)
        if self.params.stiffness == "secant":
            self.secant_, self.roof_ = secant_curve(structure, self.params.target_drift_ratio)
            squares = scipy.linalg.eigh(
                self.system_.stiffness, self.system_.mass, eigvals_only=True, subset_by_index=(0, 0)
            )
            self.omega1_ = float(np.sqrt(squares[0]))
        return self

    def transform(self, motions: GroundMotions) -> np.ndarray:
        """``[n_records, n_steps, n_outputs]`` ELS displacements in m on the motion's grid."""
        check_fitted(self, "system_")
        if self.params.stiffness == "initial":
            return linear_response(self.system_, motions.acceleration, motions.dt)
        return self._secant_response(motions)

    def _secant_response(self, motions: GroundMotions) -> np.ndarray:
        """Each record's response at the secant stiffness of its own peak roof displacement:
        the root of ``g(s) = k_sec(D(s)) / k_sec(0) - s`` by bisection on ``[s_min, 1]``
        (``g(1) <= 0 <= g(s_min)`` as the secant falls from 1 to its least value
        ``s_min``), ``iterations`` halvings; a record whose response stays elastic keeps
        ``s = 1``."""
        ratio = self.secant_[1]
        ag = motions.acceleration
        z = self._responses(ag, np.ones(ag.shape[0]), motions.dt)
        todo = np.flatnonzero(self._wanted(z) < 1.0 - 1e-12)
        low = np.full(ag.shape[0], ratio.min())
        high = np.ones(ag.shape[0])
        for _ in range(self.params.iterations):
            if todo.size == 0:
                break
            middle = 0.5 * (low[todo] + high[todo])
            z[todo] = self._responses(ag[todo], middle, motions.dt)
            above = self._wanted(z[todo]) > middle
            low[todo] = np.where(above, middle, low[todo])
            high[todo] = np.where(above, high[todo], middle)
        return z

    def _wanted(self, z: np.ndarray) -> np.ndarray:
        """``[n]`` the secant ratio at the peak roof displacement of each response."""
        displacement, ratio = self.secant_
        return np.interp(np.abs(z[:, :, self.roof_]).max(axis=1), displacement, ratio)

    def _responses(self, ag: np.ndarray, scale: np.ndarray, dt: float) -> np.ndarray:
        """``[n, T, n_outputs]`` the response of each record with its own stiffness scale."""
        z = np.empty((ag.shape[0], ag.shape[1], self.system_.output_map.shape[0]))
        for value in np.unique(scale):
            rows = np.flatnonzero(scale == value)
            z[rows] = linear_response(self._secant_system(value), ag[rows], dt)
        return z

    def _secant_system(self, scale: float) -> LinearSystem:
        """The system at ``scale`` times its stiffness, with the hysteretic damping of
        ``hysteretic_damping``."""
        stiffness = scale * self.system_.stiffness
        damping = self.system_.damping
        if self.params.hysteretic_damping:
            ratio = 2.0 / np.pi * (1.0 - scale)
            damping = damping + 2.0 * ratio / (np.sqrt(scale) * self.omega1_) * stiffness
        return dataclasses.replace(self.system_, stiffness=stiffness, damping=damping)


class SecantEquivalentLinear(EquivalentLinear):
    """``els`` whose stiffness is the secant one by default (``stiffness = "secant"``): its
    own name, so that a run can compare it with the initial-stiffness ``els``."""

    name = "els-secant"
    requires = EquivalentLinear.requires | {"pushover", "stories"}

    class Params(EquivalentLinear.Params):
        stiffness: Literal["initial", "secant"] = Field(
            "secant", description="as for els, secant by default"
        )


class ExactEquivalentLinear(EquivalentLinear):
    """``els`` on the structure's own linear system by default (``system = "exact"``): its
    own name, so that a run can compare it with the ``els`` of a structure whose
    equivalent linear system is another (the SAC frame's pushover shear building)."""

    name = "els-exact"
    requires = frozenset({"linear_system"})

    class Params(EquivalentLinear.Params):
        system: Literal["equivalent", "exact"] = Field(
            "exact", description="as for els, exact by default"
        )


def secant_curve(structure: Structure, target_drift_ratio: float) -> tuple[tuple, int]:
    """``((roof displacement [p] m, secant over initial stiffness [p]), roof output)`` of
    the structure's monotonic pushover (first mode times floor masses), up to where the
    roof turns back or the base shear stops being positive (a structure that softens past
    yield, P-Delta: no secant stiffness is left there)."""
    structure.require("pushover", "preprocessor 'els' with stiffness = 'secant'")
    structure.require("stories", "preprocessor 'els' with stiffness = 'secant'")
    stories = structure.stories()
    edp.require_heights(stories, "els with stiffness = 'secant' (a pushover by drift ratio)")
    if not stories.is_stacked:
        raise ConfigError(
            f"els with stiffness = 'secant': structure '{structure.name}' has stories that do "
            "not stand one above the other, so it has no roof displacement to read"
        )
    curve = structure.story_pushover(monotonic_protocol(target_drift_ratio))
    roof = curve.story_drift.sum(axis=1)[1:]
    secant = curve.story_shear[1:, 0] / roof
    keep = np.concatenate([[True], np.diff(roof) > 0])  # up to where the roof turns back
    keep = np.logical_and.accumulate(keep & (secant > 0.0))
    return (roof[keep], secant[keep] / secant[0]), int(stories.upper[-1])
