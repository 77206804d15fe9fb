"""Five of the six component interfaces: Structure, GroundMotionSource,
PhysicsPreprocessor, NeuralOperator and Refiner (the sixth, the story law, is in
:mod:`cphysfno_core.api.story_law`).

Every component class carries a registry ``name``, its ``kind`` and a pydantic ``Params``
model (``extra="forbid"``) that validates its constructor arguments; the constructor only
stores the validated parameters (scikit-learn style) and ``fit`` stores learned state in
attributes ending in ``_``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from pathlib import Path
from typing import Any, ClassVar, Literal, Protocol

import numpy as np
import scipy.stats
import torch
from pydantic import BaseModel, ConfigDict, ValidationError

from ..signals import (
    GroundMotions,
    LinearSystem,
    ResponseChannel,
    Responses,
    Stories,
    StoryPushover,
)
from ..signals.errors import CapabilityError, ConfigError, InputError
from ..signals.intensity import SpectrumBand


class Params(BaseModel):
    """Base of every component's parameter model: unknown fields are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True)


def format_validation_error(error: ValidationError, prefix: str = "") -> str:
    """One line per problem, each naming the field's dotted path."""
    lines = []
    for problem in error.errors():
        path = ".".join(str(p) for p in (prefix, *problem["loc"]) if p != "")
        message = problem["msg"]
        if problem["type"] == "extra_forbidden":
            message = "unknown field (remove it or check its spelling)"
        lines.append(f"{path}: {message}" if path else message)
    return "; ".join(lines)


def validate_params(params_model: type[Params], values: dict[str, Any], where: str) -> Params:
    """Validate ``values`` against ``params_model``; a failure names ``where.field``."""
    try:
        return params_model(**values)
    except ValidationError as error:
        raise ConfigError(format_validation_error(error, where)) from None


class Component:
    """Shared constructor of the non-torch components: validate and store parameters."""

    name: ClassVar[str] = ""
    kind: ClassVar[str] = ""
    Params: ClassVar[type[Params]] = Params

    def __init__(self, **params: Any) -> None:
        self.params = validate_params(self.Params, params, self.name or type(self).__name__)

    def get_params(self) -> dict[str, Any]:
        """The constructor arguments, as plain JSON-compatible values."""
        return self.params.model_dump(mode="json")

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"


class RestoringForce(Protocol):
    """Nonlinear restoring force of a structure, for projection onto a reduced basis.

    The equations of motion are ``M u'' + C u' + f(u, s) = -M r a_g`` with internal
    (hysteretic) state ``s`` evolving as ``s' = g(u, u', s)``.
    """

    n_states: int

    def initial_state(self, n_records: int) -> np.ndarray:
        """``[n_records, n_states]`` internal state of a structure at rest."""

    def force(self, u: np.ndarray, state: np.ndarray) -> np.ndarray:
        """``[n, n_dof]`` restoring force in N from displacements ``u [n, n_dof]`` (m)."""

    def state_rate(self, u: np.ndarray, velocity: np.ndarray, state: np.ndarray) -> np.ndarray:
        """``[n, n_states]`` time derivative of the internal state."""


CAPABILITIES: dict[str, str] = {
    "linear_system": "linear_system(): the structure's own linear elastic system, which its "
    "response follows at small amplitude",
    "equivalent_linear_system": "equivalent_linear_system(): a linear system that stands in "
    "for the structure (every structure with a linear_system has one: that system)",
    "restoring_force": "restoring_force(): the nonlinear restoring force with its state",
    "coarse_simulation": "simulate(motions, dt=coarser): the response on a coarser grid",
    "projected_simulation": "simulate_projected(motions, basis): the Galerkin-projected model",
    "stories": "stories(): which outputs bound each story and its height, for story drifts "
    "and floor accelerations (engineering demand parameters)",
    "pushover": "story_pushover(roof_drift_ratio, pattern): each story's static shear-drift "
    "curve under a lateral load pattern, monotonic or cyclic",
}
"""The optional capabilities of a structure, by name, with what each one provides."""

IMPLIED_CAPABILITIES = {"linear_system": "equivalent_linear_system"}
"""Capabilities that come with another one."""


class Structure(Component, ABC):
    """The high-fidelity nonlinear model that makes the training data.

    Capabilities beyond :meth:`simulate` and :meth:`periods` are optional (see
    :data:`CAPABILITIES`). A structure declares those it has, once, in the class attribute
    :attr:`capabilities`; a capability it lacks raises :class:`CapabilityError` from its
    method, and ``cphysfno_core.testing.check_structure`` checks that the declaration, the
    methods and the physics agree.

    Attributes:
        capabilities: the names of the capabilities the class provides (those implied by
            another, see :data:`IMPLIED_CAPABILITIES`, are added).
    """

    kind = "structure"
    capabilities: ClassVar[frozenset[str]] = frozenset()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        declared = frozenset(cls.capabilities)
        unknown = sorted(declared - CAPABILITIES.keys())
        if unknown:
            raise TypeError(
                f"{cls.__name__} declares unknown capabilities {unknown}; known: "
                f"{', '.join(CAPABILITIES)}"
            )
        implied = {IMPLIED_CAPABILITIES[c] for c in declared if c in IMPLIED_CAPABILITIES}
        cls.capabilities = declared | implied

    @property
    @abstractmethod
    def output_names(self) -> tuple[str, ...]:
        """Names of the output DOFs, in the order of the last axis of the responses."""

    @property
    def n_outputs(self) -> int:
        return len(self.output_names)

    @abstractmethod
    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        """Nonlinear time-history analysis of every record.

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            dt: integration step in s. ``None`` integrates on the motion's own grid and
                returns ``[n, T, n_outputs]``; a coarser step (capability
                ``"coarse_simulation"``) integrates with an unconditionally stable scheme
                on that grid and returns the response there.
        """

    def response_channels(self) -> tuple[ResponseChannel, ...]:
        """The named responses :meth:`simulate` records beside the displacements, each an
        extra channel ``[n, T, 1]`` of its :class:`Responses` (none by default). Their
        peaks are the EDP ``PR`` (:data:`cphysfno_core.edp.EDP_TABLE`)."""
        return ()

    @abstractmethod
    def periods(self, n: int | None = None) -> np.ndarray:
        """First ``n`` (default all) elastic natural periods in s, longest first."""

    def linear_system(self) -> LinearSystem:
        """M, C, elastic K, influence vector and output map of the structure's own linear
        system, which its response follows at small amplitude (capability
        ``linear_system``)."""
        raise self.missing("linear_system")

    def equivalent_linear_system(self) -> LinearSystem:
        """A linear system that stands in for the structure, e.g. for the ELS preprocessor
        (capability ``equivalent_linear_system``): :meth:`linear_system` unless the
        structure defines another (e.g. one fitted to a pushover)."""
        if "linear_system" in self.capabilities:
            return self.linear_system()
        raise self.missing("equivalent_linear_system")

    def restoring_force(self) -> RestoringForce:
        """The nonlinear restoring force with its internal state, for modal projection."""
        raise self.missing("restoring_force")

    def simulate_projected(
        self, motions: GroundMotions, basis: np.ndarray, *, substeps: int | None = None
    ) -> Responses:
        """Nonlinear response of the model Galerkin-projected onto ``basis`` (capability
        ``"projected_simulation"``), for modal reduction.

        With DOF displacements ``u = basis q`` and the equations of motion
        ``M u'' + C u' + f(u, s) = -M r a_g`` multiplied by ``basis^T`` (the internal state
        ``s`` kept whole), the reduced model is integrated on the motion's own grid from
        rest, with the ground acceleration linear between samples.

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            basis: ``[n_dof, r]`` displacement shapes with linearly independent columns,
                in the DOFs of :meth:`linear_system`.
            substeps: integration steps per sample interval; ``None`` lets the structure
                choose.

        Returns:
            The outputs of ``u`` (``[n, T, n_outputs]``, m), as :meth:`simulate` returns
            them; an invertible basis gives the full model.
        """
        raise self.missing("projected_simulation")

    def stories(self) -> Stories:
        """The structure's stories (capability ``"stories"``): for each story, the output at
        its bottom (``None`` for the ground) and at its top, and its height in m; see
        :class:`~cphysfno_core.signals.Stories`. Engineering demand parameters (peak and
        residual story drift ratios, peak floor accelerations, :mod:`cphysfno_core.edp`)
        are computed from it, for simulated and for predicted responses alike.

        A building whose outputs are its floor displacements bottom-up returns
        ``Stories.stacked(heights_m)``.
        """
        raise self.missing("stories")

    def story_pushover(
        self, roof_drift_ratio: np.ndarray, pattern: np.ndarray | None = None
    ) -> StoryPushover:
        """A static pushover (capability ``"pushover"``) of a structure whose stories are
        stacked floors (:meth:`stories`): from rest (under gravity, where the structure has
        gravity), a lateral load of a fixed shape on the floors, scaled so that the roof
        follows ``roof_drift_ratio``, returning each story's shear-drift curve.

        Args:
            roof_drift_ratio: ``[p]`` roof displacement over the building's height at each
                point, from 0: monotonic (:func:`~cphysfno_core.signals.monotonic_protocol`)
                or cyclic (:func:`~cphysfno_core.signals.cyclic_protocol`).
            pattern: ``[d]`` the load on each floor, bottom up (scaled to sum to 1);
                ``None``: the first elastic mode's floor displacements times the floor
                masses (:func:`~cphysfno_core.signals.first_mode_pattern`).

        Returns:
            The curves; a pushover that loses its strength or stops converging ends early
            and says why in ``stopped``.
        """
        raise self.missing("pushover")

    def missing(self, capability: str, needed_by: str = "") -> CapabilityError:
        """The error to raise when ``capability`` is asked of a structure that lacks it."""
        who = f"{needed_by} needs" if needed_by else "this use needs"
        have = ", ".join(sorted(self.capabilities)) or "none"
        return CapabilityError(
            f"{who} structure '{self.name}' to provide {capability}, which it does not "
            f"(its capabilities: {have}); choose another component or structure"
        )

    def require(self, capability: str, needed_by: str) -> None:
        """Raise :class:`CapabilityError` naming both parties unless ``capability`` is here."""
        if capability not in self.capabilities:
            raise self.missing(capability, needed_by)

    def write_artifacts(self, directory: Path) -> list[Path]:
        """Write what a reader of a report or a saved model should see of the structure
        itself (e.g. a pushover curve as JSON and PNG) into ``directory``; return the files.
        The default writes nothing."""
        return []


class GroundMotionSource(Component, ABC):
    """Where ground motions come from: a stochastic model or a set of records.

    Attributes:
        independent_draws: True when records are drawn independently of one another, so
            that consecutive calls ``sample(a, rng)``, ``sample(b, rng)`` with one generator
            are as valid a draw of ``a + b`` records as one call. Dataset generation then
            samples such a source in blocks and never holds all motions in memory. A
            finite record set that samples without replacement keeps the default False.
    """

    kind = "ground_motion"
    independent_draws: ClassVar[bool] = False

    @abstractmethod
    def sample(self, n: int, rng: np.random.Generator) -> GroundMotions:
        """``n`` records (a recorded set may return fewer and say so in a warning)."""

    def target_spectrum(self) -> SpectrumBand | None:
        """The response spectrum the records are made to follow, drawn under theirs in
        reports (paper Fig. 10(b)); None (the default) when there is none."""
        return None


class PhysicsPreprocessor(Component, ABC):
    """The simplified physics operator H_p: ground motion -> intermediate response z.

    Attributes:
        requires: the structure capabilities :meth:`fit` uses, declared once per class;
            :meth:`check` tests a structure for them (a composite model does when it is
            built, before any simulation or training).
        collapses: whether the simplified model can collapse (a stick whose story law
            loses its strength): a record whose z holds NaN is then its prediction of a
            collapse, which fragility and demand samples count as one, and not a record
            that could not be predicted. False (the default): NaN in z is a failure.
    """

    kind = "preprocessor"
    requires: ClassVar[frozenset[str]] = frozenset()
    collapses: ClassVar[bool] = False

    def check(self, structure: Structure) -> None:
        """Raise :class:`CapabilityError` naming both parties unless ``structure`` provides
        every capability in :attr:`requires`."""
        for capability in sorted(self.requires):
            structure.require(capability, f"preprocessor '{self.name}'")

    @abstractmethod
    def fit(self, structure: Structure) -> PhysicsPreprocessor:
        """Build the simplified model from ``structure`` (after :meth:`check`)."""

    @abstractmethod
    def transform(self, motions: GroundMotions) -> np.ndarray:
        """``[n, T, n_outputs]`` intermediate displacements z in m on the motion's grid."""

    def write_artifacts(self, directory: Path) -> list[Path]:
        """Write what a reader of a saved model or a report should see of the fitted
        simplified model (e.g. a calibration as JSON and a figure) into ``directory``;
        return the files. A ``summary.md`` among them is a Markdown fragment the report
        shows as it is. The default writes nothing."""
        return []

    def restore(self, structure: Structure, directory: Path) -> PhysicsPreprocessor:
        """Fitted again for a loaded model, from what :meth:`write_artifacts` wrote into
        ``directory`` where that suffices (a calibration that took long to make); the
        default fits on ``structure``."""
        return self.fit(structure)

    def calibration(self) -> dict[str, Any] | None:
        """What fixes this fitted preprocessor to its structure, as JSON-compatible data, for
        a family of structures to interpolate between the members it was fitted to
        (:class:`~cphysfno_core.config.calibration_surface.CalibrationSurface`): its floats
        are interpolated, its other leaves (strings, integers, booleans) are choices every
        member shares. None (the default): the preprocessor is fitted to each member."""
        return None

    def refit_params(self) -> dict[str, Any]:
        """The parameters of a preprocessor that fits another member of the family with
        this fitted one's choices (a stick's story law, say), so that the members'
        :meth:`calibration` share their non-float leaves; the default: its own."""
        return self.get_params()

    def calibrated(self, structure: Structure, calibration: dict[str, Any]) -> PhysicsPreprocessor:
        """Fitted to ``structure`` from ``calibration`` (of the form :meth:`calibration`
        gives) instead of the analysis :meth:`fit` makes.

        Raises:
            CapabilityError: the preprocessor has no calibration (the default).
        """
        raise CapabilityError(
            f"preprocessor '{self.name}' has no calibration to interpolate: it is fitted to "
            "each structure of a family"
        )


class NeuralOperator(torch.nn.Module):
    """A learned operator mapping ``[batch, T, in_channels]`` to ``[batch, T, out_channels]``.

    Subclasses take ``(in_channels, out_channels, **hyper)`` where ``hyper`` is validated
    by their ``Params`` model; they must accept any ``T``.

    Prediction and training in bfloat16 (``CompositeModel.predict(...,
    precision="bfloat16")``, ``[training] precision = "bfloat16"``) call ``forward`` (and
    its backward pass) under ``torch.autocast``: an operator built of standard torch
    modules follows it as they do; one with its own products reads the dtype it asks for
    (``torch.get_autocast_dtype``) and chooses which of its steps take it. The output may
    come back in either dtype; the caller turns it into float32. Gradients reach the
    parameters in the parameters' own dtype.
    """

    name: ClassVar[str] = ""
    kind: ClassVar[str] = "operator"
    Params: ClassVar[type[Params]] = Params

    def __init__(self, in_channels: int, out_channels: int, **hyper: Any) -> None:
        super().__init__()
        if int(in_channels) < 1 or int(out_channels) < 1:
            raise ConfigError(
                f"{self.name}: in_channels and out_channels must be >= 1, "
                f"got {in_channels} and {out_channels}"
            )
        self.in_channels = int(in_channels)
        self.out_channels = int(out_channels)
        self.params = validate_params(self.Params, hyper, self.name or type(self).__name__)

    def get_params(self) -> dict[str, Any]:
        return self.params.model_dump(mode="json")

    def zero_output_(self) -> None:
        """Make the output zero for every input while every parameter can still learn:
        the residual formulation (``u = z + output``) starts training from the physics
        response this way.

        The default zeroes the weight and bias of the last ``torch.nn.Linear`` or
        ``torch.nn.Conv1d`` among :meth:`modules` (the output layer of a network whose
        layers are registered in order); an operator whose output is made otherwise
        overrides it.

        Raises:
            CapabilityError: the operator holds no such layer.
        """
        layers = [m for m in self.modules() if isinstance(m, torch.nn.Linear | torch.nn.Conv1d)]
        if not layers:
            raise CapabilityError(
                f"operator '{self.name}' has no linear output layer to start at zero: "
                "override NeuralOperator.zero_output_"
            )
        with torch.no_grad():
            layers[-1].weight.zero_()
            if layers[-1].bias is not None:
                layers[-1].bias.zero_()


class Refiner(Component, ABC):
    """Post-processing of the operator output: refined mean and standard deviation.

    Attributes:
        calibration_split: the split :meth:`fit` is given: ``"training"`` (as the paper's
            linear regression) or ``"validation"`` (a refiner whose intervals must be
            calibrated on data the operator was not fitted to).
    """

    kind = "refiner"
    calibration_split: ClassVar[Literal["training", "validation"]] = "training"

    @abstractmethod
    def fit(
        self, z: np.ndarray, u_hat: np.ndarray, u: np.ndarray, rng: np.random.Generator
    ) -> Refiner:
        """Learn from ``[n, T, dof]`` physics z, operator output u_hat and truth u (m)."""

    @abstractmethod
    def predict(self, z: np.ndarray, u_hat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Refined ``(mean, std)``, each ``[n, T, dof]`` in m."""

    def interval(
        self, z: np.ndarray, u_hat: np.ndarray, level: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Prediction interval ``(lower, upper)``, each ``[n, T, dof]`` in m, meant to hold
        the truth with probability ``level`` (0 < level < 1).

        By default the Gaussian interval ``mean ± q std`` with ``q`` the normal quantile of
        ``(1 + level) / 2``; a refiner with calibrated intervals overrides it.
        """
        if not 0.0 < level < 1.0:
            raise InputError(f"{self.name}: level must lie in (0, 1), got {level}")
        mean, std = self.predict(z, u_hat)
        half = float(scipy.stats.norm.ppf(0.5 + level / 2.0)) * std
        return mean - half, mean + half

    @abstractmethod
    def state_dict(self) -> dict[str, np.ndarray]:
        """Fitted arrays, to save with the model."""

    @abstractmethod
    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`state_dict` returned."""
