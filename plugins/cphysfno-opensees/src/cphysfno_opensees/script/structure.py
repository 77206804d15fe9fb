"""``opensees-model``: any OpenSeesPy model a user already has, as a cphysfno structure."""

from __future__ import annotations

import functools
import json
import logging
from collections.abc import Callable
from functools import cached_property
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, PositiveFloat, field_validator, model_validator

from cphysfno_core import edp
from cphysfno_core.plugin import LinearSystem, Stories, StoryPushover
from cphysfno_core.signals import ResponseChannel

from ..runner import call_in_worker
from ..structure import OpenSeesParams, OpenSeesStructure
from .analysis import analyse
from .damping import DampingChoice, DampingKind, DampingRegion
from .model import LENGTH_UNITS, ModelSpec
from .probe import Summary, probe
from .pushover import story_pushover
from .responses import ResponseParams
from .source import ScriptError, resolve

logger = logging.getLogger(__name__)

Node = int
Dof = Literal[1, 2, 3, 4, 5, 6]
PYTHON_NAME = r"^[A-Za-z_][A-Za-z0-9_]*$"
"""A name a script's function or keyword may have."""


class OpenSeesModelParams(OpenSeesParams):
    """Parameters of :class:`OpenSeesModel`: the script and its arguments, its outputs, the
    damping, the gravity loads, the units and the constraint handler."""

    script: Path = Field(
        description="Python file defining build(), which creates the model in OpenSeesPy's "
        "domain (nodes, fixities, masses, materials, elements; no damping, loads or "
        "analysis); relative to the config file's folder in a config, else to the working "
        "directory",
    )
    arguments: dict[Annotated[str, Field(pattern=PYTHON_NAME)], float] = Field(
        {},
        description="keyword arguments given to the script's build() and gravity functions, "
        "numbers in the script's own units: each function gets those its signature accepts "
        "(all with **kwargs); one that neither accepts is an error",
    )
    outputs: list[tuple[Node, Dof]] = Field(
        min_length=1,
        description="[node, dof] of each output: its displacement relative to the ground "
        "is predicted (dof counted from 1)",
    )
    output_names: list[str] | None = Field(
        None, description="a name for each output (default node-<node>-dof-<dof>)"
    )
    excitation_dof: Dof = Field(1, description="the DOF along which the ground moves")
    damping: DampingKind = Field(
        "rayleigh",
        description="rayleigh: mass and initial stiffness; rayleigh-committed: mass and "
        "committed stiffness; modal: OpenSees modalDamping over the modes at the gravity state",
    )
    damping_ratio: float = Field(
        0.05,
        ge=0.0,
        lt=1.0,
        description="damping ratio: in rayleigh_modes for Rayleigh damping, in every mode "
        "for modal damping unless modal_ratios gives one per mode",
    )
    rayleigh_modes: tuple[int, int] = Field(
        (1, 2), description="the two modes (from 1, at the gravity state) damped damping_ratio"
    )
    modal_ratios: list[Annotated[float, Field(ge=0.0, lt=1.0)]] | None = Field(
        None,
        min_length=1,
        description="modal damping: the ratio of each mode from 1 (the modes after them "
        "undamped); default damping_ratio in every mode",
    )
    damping_region: DampingRegion | None = Field(
        None,
        description="Rayleigh damping on these nodes' masses and elements' stiffness only "
        "(leave isolators or zeroLength springs undamped); default the whole model",
    )
    gravity: str | None = Field(
        None,
        pattern=PYTHON_NAME,
        description="name of a function of the script that applies the gravity loads (and "
        "may analyse them itself); they are held constant during the record",
    )
    story_heights: list[PositiveFloat] | None = Field(
        None,
        description="height of each story in length_unit, the outputs being its floors "
        "bottom-up (for story drift ratios; default: from the outputs' elevations)",
    )
    drift_pairs: list[tuple[Node, Node]] | None = Field(
        None,
        description="[lower node, upper node] of each story (the lower a restrained node for "
        "the ground story); heights from the nodes' coordinates",
    )
    length_unit: Literal["m", "cm", "mm", "in", "ft"] = Field(
        "m",
        description="the script's length unit (time in s; force and mass as the script has "
        "them): records are converted into it, outputs come back in m",
    )
    constraints: Literal["auto", "Plain", "Penalty", "Transformation", "Lagrange"] = Field(
        "auto",
        description="OpenSees constraint handler of every analysis; auto checks "
        "Transformation against the exactly constrained model and falls back to Penalty",
    )
    tolerance: float = Field(
        1e-8,
        gt=0.0,
        description="Newton's tolerance on the norm of the displacement increment, m",
    )
    max_iterations: int = Field(
        25, ge=1, description="Newton iterations per step before the fallbacks"
    )
    responses: list[ResponseParams] = Field(
        [],
        description="named node or element responses recorded beside the outputs (base "
        "shear, isolator force or deformation, ...), each with its unit",
    )

    @field_validator("rayleigh_modes")
    @classmethod
    def _modes_from_one(cls, modes: tuple[int, int]) -> tuple[int, int]:
        if min(modes) < 1:
            raise ValueError("modes are counted from 1")
        return modes

    @model_validator(mode="after")
    def _consistent(self) -> OpenSeesModelParams:
        n = len(self.outputs)
        if len(set(self.outputs)) != n:
            raise ValueError("outputs: each [node, dof] may appear once")
        if self.output_names is not None:
            if len(self.output_names) != n or len(set(self.output_names)) != n:
                raise ValueError(f"output_names: give {n} distinct names, one per output")
        if self.story_heights is not None and self.drift_pairs is not None:
            raise ValueError("give story_heights or drift_pairs, not both")
        if self.story_heights is not None and len(self.story_heights) != n:
            raise ValueError(f"story_heights: give one per output ({n}), bottom story first")
        if self.modal_ratios is not None and self.damping != "modal":
            raise ValueError("modal_ratios: only with damping = 'modal'")
        if self.damping_region is not None and self.damping == "modal":
            raise ValueError("damping_region: only with Rayleigh damping (modal acts on all)")
        names = [r.name for r in self.responses]
        clashes = sorted(
            {n for n in names if names.count(n) > 1}
            | ({*names} & {edp.ACCELERATION_EXTRA, "displacement"})
        )
        if clashes:
            raise ValueError(f"responses: the names {', '.join(clashes)} are taken")
        return self


class OpenSeesModel(OpenSeesStructure):
    """A user's own OpenSeesPy model under horizontal (or any single-DOF) ground motion.

    The script's ``build()`` creates the model, given the keywords of ``arguments`` its
    signature accepts; the framework adds the rest:

    - gravity: the script's function ``gravity`` (if named; given its keywords of
      ``arguments`` as ``build()`` is) applies the gravity loads and may analyse them
      itself; if it leaves them unanalysed the framework analyses them statically; either
      way they are held constant (``loadConst -time 0.0``) before the record, so P-Delta
      acts through the element transformations the script chose;
    - damping (``damping``): Rayleigh on the mass and the initial stiffness (``alphaM``,
      ``betaKinit``; ``rayleigh``) or the committed stiffness (``betaKcomm``;
      ``rayleigh-committed``), ``damping_ratio`` in ``rayleigh_modes`` of the model at its
      gravity state, on the whole model or on ``damping_region`` only (OpenSees
      ``region``); or OpenSees' ``modalDamping`` (``modal``) over the modes of an eigen
      analysis at the gravity state, ``damping_ratio`` in each or ``modal_ratios``;
    - the record: a UniformExcitation along ``excitation_dof`` on the record's own time
      step, Newmark's average acceleration rule with Newton iterations, the fallbacks of
      :func:`~cphysfno_opensees.transient.integrate` and the worker recycling of
      :func:`~cphysfno_opensees.runner.run_records`; a record that does not converge is
      reported in ``Responses.failures``;
    - the constraint handler of every analysis (gravity, eigen, transient): with
      ``constraints = "auto"``, ``Transformation`` if it reproduces the exactly constrained
      model (its gravity state and eigenvalues), else ``Penalty``;
    - units: records are converted into ``length_unit`` before they are applied, and
      outputs come back in m (rad for rotations).

    Its periods and linear system are those of the tangent at the gravity state: mass,
    stiffness and damping as OpenSees assembles them there, the constrained DOFs
    eliminated and the massless ones condensed statically
    (:mod:`cphysfno_opensees.matrices`), in m and rad and the script's force unit.
    """

    name = "opensees-model"
    Params = OpenSeesModelParams
    capabilities = frozenset({"linear_system", "coarse_simulation", "stories", "pushover"})

    @property
    def output_names(self) -> tuple[str, ...]:
        if self.params.output_names is not None:
            return tuple(self.params.output_names)
        return tuple(f"node-{node}-dof-{dof}" for node, dof in self.params.outputs)

    @property
    def metres_per_unit(self) -> float:
        """Metres per length unit of the script."""
        return LENGTH_UNITS[self.params.length_unit]

    @cached_property
    def spec(self) -> ModelSpec:
        """The model for the worker processes (its constraint handler not yet chosen).

        Raises:
            ScriptError: the script does not exist.
        """
        p = self.params
        return ModelSpec(
            script=resolve(p.script),
            outputs=tuple((int(node), int(dof)) for node, dof in p.outputs),
            excitation_dof=int(p.excitation_dof),
            gravity=p.gravity,
            metres_per_unit=self.metres_per_unit,
            tolerance=p.tolerance / self.metres_per_unit,
            max_iterations=p.max_iterations,
            responses=tuple(p.responses),
            arguments=tuple(p.arguments.items()),
        )

    @property
    def damping_choice(self) -> DampingChoice:
        """The damping the parameters ask for (its factors found by the probe)."""
        p = self.params
        return DampingChoice(
            p.damping,
            p.damping_ratio,
            tuple(p.rayleigh_modes),
            None if p.modal_ratios is None else tuple(p.modal_ratios),
            p.damping_region,
        )

    @cached_property
    def summary(self) -> Summary:
        """The model as probed in a worker process: its constraint handler, damping and
        linear equations at the gravity state (once per instance).

        Raises:
            ScriptError: the script fails, a keyword of ``arguments`` is taken by none of
                its functions, or the model cannot be analysed.
            PluginError: the probe's process died (OpenSees ended it).
        """
        p = self.params
        summary = call_in_worker(
            probe,
            self.spec,
            p.constraints,
            self.damping_choice,
            description=f"probing the model of OpenSees script {self.spec.script}",
        )
        logger.info(
            "%s: %s, constraints %s (%s)",
            self.name,
            self.spec.script,
            summary.constraints[0],
            "; ".join(f"{h}: {finding}" for h, finding in summary.checks),
        )
        return summary

    @property
    def constraints_handler(self) -> str:
        """The OpenSees constraint handler every analysis of the model uses."""
        return str(self.summary.constraints[0])

    def analysis(self) -> Callable[[np.ndarray, float], np.ndarray]:
        """One record's analysis: :func:`~.analysis.analyse` with the model, its handler
        its damping and its convergence ladder bound."""
        summary = self.summary
        spec = self.spec.with_constraints(summary.constraints)
        return functools.partial(analyse, spec, summary.damping_setup, self.params.convergence)

    def response_channels(self) -> tuple[ResponseChannel, ...]:
        """The named ``responses``, each an extra channel ``[n, T, 1]`` in its unit."""
        return tuple(r.channel() for r in self.params.responses)

    def ground_influence(self) -> np.ndarray:
        """``[n_outputs]``: 1 for an output along the excitation DOF (a translation, which
        the ground's acceleration adds to), 0 for the others."""
        return np.array([float(dof == self.params.excitation_dof) for _, dof in self.spec.outputs])

    def linear_system(self) -> LinearSystem:
        """The equations at the gravity state (:class:`OpenSeesModel`), in m and rad and the
        script's force unit (N, and so kg, for a script in SI units)."""
        summary = self.summary
        f = self.metres_per_unit
        translation = np.array([dof <= summary.ndm for _, dof in summary.dofs])
        to_si = np.where(translation, f, 1.0)  # u_si = to_si * u_model
        scale = f / np.outer(to_si, to_si)
        outputs = np.array([dof <= summary.ndm for _, dof in self.spec.outputs])
        out_scale = np.where(outputs, f, 1.0)
        return LinearSystem(
            summary.mass * scale,
            summary.damping * scale,
            summary.stiffness * scale,
            summary.influence * to_si / f,
            summary.output_map * out_scale[:, None] / to_si[None, :],
        )

    def stories(self) -> Stories:
        """The stories for drift ratios and floor accelerations, from the parameters:

        - ``story_heights``: the outputs are the floors bottom-up, story ``s`` from output
          ``s - 1`` (the ground for the first) to output ``s``, of the given heights;
        - ``drift_pairs``: each story from the output at its lower node (or the ground,
          for a restrained node) to the output at its upper node, its height the
          difference of the nodes' vertical coordinates;
        - neither: from the outputs along ``excitation_dof`` and their nodes' elevations
          (the last coordinate: y in 2D, z in 3D). Outputs at distinct elevations are
          floors one above the other (the lowest over the ground, the elevation of the
          lowest restrained node); where several share an elevation (piers, or joints of
          one floor), each is a story from the ground; where every output stands at the
          ground's elevation (a shear building of ``zeroLength`` springs), the outputs in
          their order are floors one above the other.

        Heights are converted to m from ``length_unit``. A story whose ends stand at one
        elevation (``zeroLength`` springs, an isolator) has no height (``nan``): its drift
        is reported in m, and what needs drift ratios (fragility on PID, pelicun demands)
        asks for ``story_heights`` or ``drift_pairs``.

        Raises:
            ScriptError: a node of ``drift_pairs`` is not an output along the excitation
                (nor, for the lower one, restrained), or the stories cannot be told from
                the model (a one-dimensional model, no output along the excitation): give
                ``story_heights`` or ``drift_pairs``.
        """
        p = self.params
        f = self.metres_per_unit
        if p.story_heights is not None:
            return Stories.stacked(tuple(h * f for h in p.story_heights))
        summary = self.summary
        along = {
            node: i
            for i, (node, dof) in reversed(list(enumerate(self.spec.outputs)))
            if dof == p.excitation_dof
        }
        if summary.ndm < 2 or not along:
            raise ScriptError(
                f"{self.name}: the stories of OpenSees script {self.spec.script} cannot be told "
                "from its model (no vertical coordinate, or no output along excitation_dof): "
                "give story_heights or drift_pairs"
            )
        axis = summary.ndm - 1

        def elevation(node: int) -> float:
            return summary.coordinates[node][axis] * f

        # (output at the bottom or None, elevation of the bottom, node at the top)
        spans: list[tuple[int | None, float, int]] = []
        if p.drift_pairs is None:
            ground = min(map(elevation, summary.restrained or summary.coordinates))
            floors = sorted(along, key=elevation)
            levels = [elevation(node) for node in floors]
            if all(level == ground for level in levels):  # zeroLength stories: output order
                floors = sorted(along, key=along.__getitem__)
                below = [None, *floors[:-1]]
                for bottom, top in zip(below, floors, strict=True):
                    spans.append((None if bottom is None else along[bottom], ground, top))
            elif len(set(levels)) == len(levels):
                below = [None, *floors[:-1]]
                for bottom, top in zip(below, floors, strict=True):
                    base = ground if bottom is None else elevation(bottom)
                    spans.append((None if bottom is None else along[bottom], base, top))
            else:
                spans = [(None, ground, node) for node in sorted(along, key=along.__getitem__)]
        else:
            for bottom, top in p.drift_pairs:
                if top not in along:
                    raise ScriptError(
                        f"drift_pairs: node {top} is not an output along excitation_dof "
                        f"{p.excitation_dof}"
                    )
                if bottom not in along and bottom not in summary.restrained:
                    raise ScriptError(
                        f"drift_pairs: node {bottom} is neither an output along excitation_dof "
                        f"{p.excitation_dof} nor restrained (the ground)"
                    )
                spans.append((along.get(bottom), elevation(bottom), top))
        lower, upper, heights = [], [], []
        for bottom, base, top in spans:
            height = abs(elevation(top) - base)
            if not height > 0.0:
                height = float("nan")  # zeroLength springs: a drift in m, not a ratio
            lower.append(bottom)
            upper.append(along[top])
            heights.append(height)
        return Stories(tuple(lower), tuple(upper), tuple(heights))

    def story_pushover(
        self, roof_drift_ratio: np.ndarray, pattern: np.ndarray | None = None
    ) -> StoryPushover:
        """The pushover of the model at its gravity state, in a worker process
        (:func:`~.pushover.story_pushover`); story shears in the script's force unit."""
        spec = self.spec.with_constraints(self.summary.constraints)
        system = self.linear_system()
        return story_pushover(spec, self.stories(), system, roof_drift_ratio, pattern)

    def write_artifacts(self, directory: Path) -> list[Path]:
        """``opensees-model.json``: the constraint handler chosen and why, the damping
        (Rayleigh factors, region, modal ratios), the periods at the gravity state (the
        framework's and OpenSees' own eigen analysis) and the DOFs of the linear system."""
        summary = self.summary
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        document = directory / "opensees-model.json"
        document.write_text(
            json.dumps(
                {
                    "script": str(self.spec.script),
                    "arguments": self.spec.keywords,
                    "constraints": list(summary.constraints),
                    "constraint_checks": [list(check) for check in summary.checks],
                    "damping": summary.damping_setup.describe(),
                    "periods_s": summary.periods().tolist(),
                    "opensees_eigen_periods_s": summary.opensees_periods.tolist(),
                    "linear_system_dofs": [list(dof) for dof in summary.dofs],
                    "length_unit": self.params.length_unit,
                },
                indent=2,
            )
        )
        return [document]
