"""The SAC Los Angeles nine-story steel moment frame of the paper's Example 3 (§5.3)."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from cphysfno_core import ConfigError
from cphysfno_core.plugin import LinearSystem, Rayleigh, Stories, StoryPushover

from ..loader import import_opensees
from ..pushover import (
    STRENGTH_LOSS,
    Pushed,
    PushoverCurve,
    plot_pushover,
    push,
    run_pushover,
    shear_building,
    story_pushover_by,
)
from ..runner import call_in_worker
from ..structure import OpenSeesParams, OpenSeesStructure
from .analysis import SolverConfig, analyse_record
from .elastic import condensed_system
from .model import FrameConfig, build_frame, eigenvalues
from .sections import N_STORIES, level_heights

__all__ = ["Sac9Frame", "Sac9FrameParams", "plot_pushover"]


class Sac9FrameParams(OpenSeesParams):
    """Parameters of :class:`Sac9Frame`; the published data (geometry, shapes, steel,
    masses) are fixed, these are the modelling and solution choices."""

    model: Literal["fibre", "hinges"] = Field(
        "fibre",
        description="fibre: force-based elements with fibre sections; hinges: elastic "
        "members with bilinear moment-curvature hinges at their ends (faster)",
    )
    damping_ratio: float = Field(
        0.03, ge=0.0, lt=1.0, description="Rayleigh damping ratio in modes 1 and 3"
    )
    p_delta: bool = Field(
        True, description="P-Delta columns and a leaning column carrying the floors' weight"
    )
    flange_fibres: int = Field(
        2, ge=2, le=50, description="fibres through each flange (Gauss-Legendre points)"
    )
    web_fibres: int = Field(
        16, ge=4, le=200, multiple_of=2, description="fibres over the web depth, even"
    )
    integration_points: int = Field(
        5, ge=3, le=10, description="Gauss-Lobatto points per fibre element"
    )
    elastic_interior: bool = Field(
        True,
        description="fibre sections at the two end points only, elastic sections of the "
        "same EA and EI inside (identical while the interior stays below first yield)",
    )
    hinge_length: float = Field(
        0.5, gt=0.0, le=2.0, description="plastic hinge length over the member depth (hinges)"
    )
    tolerance: float = Field(
        100.0,
        gt=0.0,
        le=1e4,
        description="largest norm of the unbalanced nodal forces of a converged step, N",
    )
    elastic_phases: bool = Field(
        True,
        description="fibre model: take the phases in which every fibre stays elastic from "
        "the exact condensed linear model and run OpenSees only between them (no OpenSees "
        "analysis for a record that never yields)",
    )
    pushover_drift: float = Field(
        0.03, gt=0.0, le=0.1, description="roof drift ratio the pushover reaches"
    )


class Sac9Frame(OpenSeesStructure):
    """Two-dimensional OpenSees model of one north-south moment frame of the SAC Los
    Angeles nine-story building (Ohtori et al. 2004), under horizontal ground motion.

    Five 9.144 m bays, a 3.66 m basement on pinned column bases, the ground level held
    horizontally, a 5.49 m first story and 3.96 m stories above; W-shape columns
    (F_y = 345 MPa) changing section at the splices of stories 1, 3, 5 and 7 and beams
    (F_y = 248 MPa), bilinear steel with 1 % hardening, the rightmost bay's beams pinned at
    the exterior column; half the building's seismic mass on rigid-diaphragm floors, a
    leaning column carrying that weight through P-Delta, Rayleigh damping on the mass and
    the initial stiffness. The equations are integrated with Newmark's average
    acceleration rule, one step per sample, the ground acceleration linear between samples.

    Outputs are the horizontal displacements of levels 2 ... 9 and the roof relative to
    the ground (m). Records run in worker processes and a coarser ``dt`` resamples the
    motion (:class:`~cphysfno_opensees.structure.OpenSeesStructure`). Two linear systems:
    :meth:`linear_system`, the frame's own condensed exactly to its floors, and
    :meth:`equivalent_linear_system`, the paper's, the shear building whose story
    stiffnesses come from a pushover of this model (the ``els`` preprocessor's); the
    periods are the frame's own.
    """

    name = "sac9-frame"
    Params = Sac9FrameParams
    capabilities = frozenset({"linear_system", "coarse_simulation", "stories", "pushover"})

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(f"level-{level}" for level in range(2, N_STORIES + 1)) + ("roof",)

    def stories(self) -> Stories:
        """Nine stories, one above the other, the outputs being the floors bottom-up: the
        first from the ground (level 1) to level 2, 5.49 m, the eight above 3.96 m each, up
        to the roof."""
        ground_to_roof = np.asarray(level_heights()[1:])
        return Stories.stacked(tuple(np.diff(ground_to_roof).tolist()))

    @property
    def frame_config(self) -> FrameConfig:
        """The model these parameters describe."""
        p = self.params
        return FrameConfig(
            model=p.model,
            flange_fibres=p.flange_fibres,
            web_fibres=p.web_fibres,
            integration_points=p.integration_points,
            elastic_interior=p.elastic_interior,
            hinge_length=p.hinge_length,
            p_delta=p.p_delta,
            damping_ratio=p.damping_ratio,
        )

    @property
    def solver_config(self) -> SolverConfig:
        """How each step is solved."""
        p = self.params
        phases = p.elastic_phases and p.model == "fibre"
        # Full Newton for the yielding steps OpenSees is left with; from rest, where most
        # steps are elastic, a tangent factorised once is faster.
        algorithm = ("Newton",) if phases else ("ModifiedNewton", "-FactorOnce")
        return SolverConfig(
            tolerance=p.tolerance,
            algorithm=algorithm,
            convergence=p.convergence,
            elastic_phases=phases,
        )

    def analysis(self) -> Callable[[np.ndarray, float], np.ndarray]:
        """``analyse(a_g [T] m/s^2, dt s) -> [T, 9]`` floor displacements (m): the model,
        the solver settings and the Rayleigh coefficients bound to
        :func:`~cphysfno_opensees.sac9.analysis.analyse_record`."""
        return functools.partial(
            analyse_record, self.frame_config, self.solver_config, self.rayleigh()
        )

    def periods(self, n: int | None = None) -> np.ndarray:
        """First ``n`` (default all nine) elastic periods in s, longest first, from an
        OpenSees eigen analysis of the initial stiffness with the P-Delta effect of the
        floors' weight (as the frame responds at small amplitude, and as its
        :meth:`linear_system`); Rayleigh damping is matched to these."""
        return _periods(self.frame_config, loaded=True)[: self._count(n)].copy()

    def unloaded_periods(self, n: int | None = None) -> np.ndarray:
        """First ``n`` (default all nine) periods in s without the P-Delta effect of the
        weight (the model "before gravity", about 3 % shorter: the published periods are
        of this kind)."""
        return _periods(self.frame_config, loaded=False)[: self._count(n)].copy()

    def _count(self, n: int | None) -> int:
        if n is None:
            return N_STORIES
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= N_STORIES:
            raise ConfigError(f"{self.name}: n must be an integer from 1 to {N_STORIES}, got {n!r}")
        return int(n)

    def pushover(self) -> PushoverCurve:
        """The pushover of the nonlinear model (fibre sections at every integration point,
        whatever ``elastic_interior`` says) under an inverted triangular load, to a roof
        drift ratio of ``pushover_drift``; computed once per model.

        Raises:
            PushoverError: the pushover did not converge, or never left the elastic range.
        """
        config = dataclasses.replace(self.frame_config, elastic_interior=False)
        return _pushover(config, self.params.pushover_drift)

    def story_pushover(
        self, roof_drift_ratio: np.ndarray, pattern: np.ndarray | None = None
    ) -> StoryPushover:
        """Each story's shear-drift curve of the nonlinear model (fibre sections at every
        integration point, the P-Delta of the weight), pushed in a worker process along
        ``roof_drift_ratio`` by ``pattern`` on the floors (default: the first mode of
        :meth:`linear_system` times the floor masses); story shears in N, drifts in m
        (:func:`~cphysfno_opensees.pushover.story_pushover_by`). It stops early, saying so,
        where a step does not converge or the base shear drops by
        :data:`~cphysfno_opensees.pushover.STRENGTH_LOSS` on a new excursion."""
        config = dataclasses.replace(self.frame_config, elastic_interior=False)

        def pusher(shape: np.ndarray, roof: np.ndarray) -> Pushed:
            return call_in_worker(
                _push_frame, config, shape, roof, description="pushing the SAC frame"
            )

        return story_pushover_by(
            pusher, self.stories(), self.linear_system(), roof_drift_ratio, pattern
        )

    def write_artifacts(self, directory: Path) -> list[Path]:
        """The pushover behind the equivalent linear system: ``pushover.json`` (the curve,
        the initial slope and the story stiffnesses, SI units) and ``pushover.png``."""
        curve = self.pushover()
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        document = directory / "pushover.json"
        document.write_text(curve.to_json())
        figure = directory / "pushover.png"
        plot_pushover(curve, figure)
        return [document, figure]

    def linear_system(self) -> LinearSystem:
        """The frame's own linear system: the model condensed exactly to its nine floors
        while it is elastic (:func:`~.elastic.condensed_system`: floor masses in kg, the
        lateral stiffness in N/m with the P-Delta effect of the weight, the Rayleigh
        damping of the analyses); influence ones, identity output map: its periods are
        :meth:`periods`. The ``els-exact`` preprocessor solves it; ``els`` solves the
        paper's :meth:`equivalent_linear_system`."""
        masses, stiffness, damping = condensed_system(self.frame_config, self.rayleigh())
        n = masses.size
        return LinearSystem(np.diag(masses), damping, stiffness, np.ones(n), np.eye(n))

    def equivalent_linear_system(self) -> LinearSystem:
        """The paper's equivalent linear system: the shear building of the pushover's
        elastic story stiffnesses (N/m) and the floor masses (kg), Rayleigh damped with
        ``damping_ratio`` in its modes 1 and 3; influence ones, identity output map."""
        curve = self.pushover()
        config = self.frame_config
        return shear_building(
            curve.masses, curve.story_stiffness, config.damping_ratio, config.damping_modes
        )

    def rayleigh(self) -> Rayleigh:
        """Rayleigh coefficients on the mass and the initial stiffness that give
        ``damping_ratio`` in modes 1 and 3 of the model with its P-Delta effect."""
        config = self.frame_config
        omega = 2.0 * np.pi / self.periods()
        first, second = (omega[m - 1] for m in config.damping_modes)
        return Rayleigh.matching(first, second, config.damping_ratio)


@functools.lru_cache(maxsize=16)
def _periods(config: FrameConfig, loaded: bool) -> np.ndarray:
    """``[9]`` periods in s of the model at rest, without (``loaded=False``: no P-Delta) or
    with the P-Delta effect of its weight."""
    ops = import_opensees()
    frame = build_frame(ops, config if loaded else dataclasses.replace(config, p_delta=False))
    squares = eigenvalues(ops, len(frame.floors))
    ops.wipe()
    return 2.0 * np.pi / np.sqrt(squares)


@functools.lru_cache(maxsize=16)
def _pushover(config: FrameConfig, target_drift_ratio: float) -> PushoverCurve:
    ops = import_opensees()
    frame = build_frame(ops, config)
    try:
        return run_pushover(
            ops,
            frame.floors,
            frame.heights,
            frame.masses,
            target_drift_ratio=target_drift_ratio,
            configure=_static_solver,
        )
    finally:
        ops.wipe()


def _push_frame(config: FrameConfig, pattern: np.ndarray, roof: np.ndarray) -> Pushed:
    """Build the frame and :func:`~cphysfno_opensees.pushover.push` it along ``roof`` (m)
    by ``pattern`` on its floors (runs in a worker process)."""
    ops = import_opensees()
    try:
        frame = build_frame(ops, config)
        _static_solver(ops)
        return push(ops, list(frame.floors), 1, pattern, roof, STRENGTH_LOSS)
    finally:
        ops.wipe()


def _static_solver(ops) -> None:
    """Solver of the pushover: full Newton on a general banded system (the tangent may lose
    definiteness past the peak), equations numbered in tag order."""
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-8, 50)
    ops.algorithm("Newton")
