"""The composite model: physics preprocessor H_p, normalisers, neural operator G_θ and an
optional refiner. :mod:`.assembly` builds one from parts, :mod:`.persistence` saves and
loads it."""

from __future__ import annotations

import copy
import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from ..api.interfaces import (
    NeuralOperator,
    PhysicsPreprocessor,
    Refiner,
    Structure,
)
from ..api.registry import get_registry
from ..config.allocator import tune_memory
from ..config.calibration_surface import CalibrationSurface, member_preprocessor
from ..config.experiment import ComponentSpec, FormulationConfig, TrainingConfig
from ..config.precision import Precision, operator_precision
from ..config.uncertainty import distinct_draws, value_at, with_values
from ..signals import GroundMotions, TimeGrid, as_ground_motions
from ..signals.errors import (
    ConfigError,
    InputError,
    NotFittedError,
)
from ..signals.histories import ACCELERATION_EXTRA
from ..signals.intensity import peak_ground_acceleration
from .extrapolation import warn_extrapolation
from .labels import ModelLabel
from .parameters import ParameterScale, ParameterValues
from .parts import PartLike, resolve
from .persistence import load_model, save_model
from .training import (
    EpochReport,
    Normalizer,
    TrainingHistory,
    print_progress,
    resolve_device,
    train_operator,
)

MEMBERS_KEPT = 256
"""How many members of a family (their fitted preprocessors, by draw) a model keeps
between predictions."""

PREDICT_CHUNK = 8
"""Records per operator call in prediction: the activations of a chunk (a few MiB per
record at the paper's sizes) stay small and are reused from chunk to chunk."""


def _kinds_stacked(*kinds: np.ndarray | None) -> np.ndarray:
    """``[n, T, channels]`` the response kinds given (displacements, accelerations, named
    responses; None where a model does not learn one) side by side, in the order of the
    operator's output channels."""
    return np.concatenate([kind for kind in kinds if kind is not None], axis=2)


def _rows_of(array: np.ndarray | None, rows: slice | np.ndarray) -> np.ndarray | None:
    return None if array is None else array[rows]


@dataclass
class Prediction:
    """Every stage of a composite prediction, each ``[n, T, dof]`` in m (z None for a
    baseline without physics); ``operator_output`` is the operator's prediction û of the
    displacements, z included for a residual formulation. ``acceleration`` is the
    operator's prediction of the outputs' absolute accelerations ``[n, T, dof]`` in m/s^2
    for a model that learns them (``formulation.accelerations``), else None;
    ``responses`` its prediction of each named response ``[n, T, 1]`` (in the channel's
    unit) for a model that learns them (``formulation.responses``), else empty."""

    z: np.ndarray | None
    operator_output: np.ndarray
    mean: np.ndarray
    std: np.ndarray
    acceleration: np.ndarray | None = None
    responses: dict[str, np.ndarray] = field(default_factory=dict)

    def extras(self) -> dict[str, np.ndarray]:
        """The predicted channels beside the displacement, by their names as
        :class:`~cphysfno_core.signals.Responses` extras: the absolute accelerations
        (``absolute_acceleration``) and the named responses, those the model learns."""
        found = {} if self.acceleration is None else {ACCELERATION_EXTRA: self.acceleration}
        return {**found, **self.responses}


class CompositeModel:
    """``a_g -> H_p -> z -> G_θ -> û -> refiner -> (mean, std)``.

    Without a preprocessor it is the plain neural-operator baseline on ``[a_g, t]``.
    Without a refiner, ``std`` is the operator's validation RMSE per DOF.

    Construction stores the parts (and checks that the structure has the capabilities
    the preprocessor requires); :meth:`fit` fits the preprocessor to the structure and
    trains. Build one with :func:`~cphysfno_core.compose`; :meth:`save` / :meth:`load`.

    A model fitted with ``params`` (each training record's values of the structure's
    random parameters) is a model of a family of structures: at prediction each record's
    ``params`` rebuild its structure for its physics response, and with
    ``formulation.parameter_input`` they also enter the operator as constant input
    channels (see :mod:`.parameters`). With a ``calibration_surface`` (of its
    preprocessor over the family, :mod:`.calibration_surface`) each record's preprocessor
    is fitted from the calibration the surface gives at its parameters, not by the
    preprocessor's own analysis.
    """

    def __init__(
        self,
        operator: ComponentSpec | NeuralOperator,
        structure: Structure | None = None,
        preprocessor: PhysicsPreprocessor | None = None,
        refiner: Refiner | None = None,
        training: TrainingConfig | None = None,
        formulation: FormulationConfig | None = None,
        calibration_surface: CalibrationSurface | None = None,
    ) -> None:
        if preprocessor is not None and structure is None:
            raise ConfigError("a physics preprocessor needs the structure it simplifies")
        if calibration_surface is not None and (
            preprocessor is None or calibration_surface.preprocessor["name"] != preprocessor.name
        ):
            own = calibration_surface.preprocessor["name"]
            other = "no preprocessor" if preprocessor is None else repr(preprocessor.name)
            raise ConfigError(
                f"a calibration surface of preprocessor '{own}' serves a model of that "
                f"preprocessor, not of {other}"
            )
        self.structure = structure
        self.preprocessor = preprocessor
        self.calibration_surface = calibration_surface
        self._members: dict[tuple[float, ...], PhysicsPreprocessor] = {}
        self.refiner = refiner
        self.training = training or TrainingConfig()
        self.formulation = formulation or FormulationConfig()
        if preprocessor is None and self.formulation != self.formulation.physics_free():
            raise ConfigError(
                "residual and ground_motion_input work on a physics response: the baseline "
                "operator has none (it always sees a_g)"
            )
        for name, value in (("residual", "choose"), ("parameter_input", "both")):
            if getattr(self.formulation, name) == value:
                raise ConfigError(
                    f"formulation.{name} = '{value}' is for a run, which trains both forms: "
                    "a model takes true or false"
                )
        if isinstance(operator, NeuralOperator):
            self.operator_spec = ComponentSpec.of(operator.name, operator.get_params())
            self.operator_ = operator
        else:
            self.operator_spec = operator
            self.operator_ = None
        if preprocessor is not None:
            preprocessor.check(structure)

    @property
    def label(self) -> str:
        """Name of this model in reports (see :class:`~cphysfno_core.model.labels.ModelLabel`)."""
        preprocessor = None if self.preprocessor is None else self.preprocessor.name
        label = ModelLabel(
            self.operator_spec.name,
            preprocessor,
            refined=self.refiner is not None,
            residual=bool(self.formulation.residual),
            parameters=bool(self.formulation.parameter_input),
        )
        return str(label)

    # -- features --------------------------------------------------------------------
    @property
    def parameters(self) -> ParameterScale | None:
        """The structural parameters this model takes (None: a model of one structure)."""
        return getattr(self, "parameters_", None)

    def physics(
        self, motions: GroundMotions, params: ParameterValues | None = None
    ) -> np.ndarray | None:
        """``[n, T, dof]`` intermediate response z in m (None for the baseline); for a
        model of a family, each record's from the structure of its ``params`` (see
        :meth:`predict_stages`)."""
        return self._physics(motions, self._parameter_values(params, motions.n_records))

    def _physics(self, motions: GroundMotions, values: np.ndarray | None) -> np.ndarray | None:
        """:meth:`physics` at the parameter values ``[n, k]`` (None: the structure's
        own): the preprocessor of the structure of each distinct draw (:meth:`_member`)."""
        if self.preprocessor is None:
            return None
        if values is None:
            return self.preprocessor.transform(motions)
        z = np.empty((*motions.acceleration.shape, self.structure.n_outputs))
        for row, rows in distinct_draws(values):
            z[rows] = self._member(tuple(row.tolist())).transform(motions[rows])
        return z

    def _member(self, row: tuple[float, ...]) -> PhysicsPreprocessor:
        """The preprocessor fitted to the structure at the parameter values ``row`` (from
        the calibration surface where the model has one), kept for the next call with that
        draw: the :data:`MEMBERS_KEPT` drawn last."""
        members = self._members
        if row in members:
            members[row] = members.pop(row)  # the newest again
            return members[row]
        drawn = dict(zip(self.parameters.names, row, strict=True))
        member = with_values(self.structure.get_params(), drawn)
        structure = get_registry().create("structure", self.structure.name, **member)
        spec = {"name": self.preprocessor.name, **self.preprocessor.get_params()}
        preprocessor = member_preprocessor(spec, structure, drawn, self.calibration_surface)
        members[row] = preprocessor
        while len(members) > MEMBERS_KEPT:
            members.pop(next(iter(members)))
        return preprocessor

    def _parameter_values(self, params: ParameterValues | None, n: int) -> np.ndarray | None:
        """``[n, k]`` each record's parameter values (those ``params`` leaves out at the
        structure's own), or None for a model of one structure.

        Raises:
            InputError: ``params`` given to a model of one structure, or invalid
                (:meth:`ParameterScale.values`).
        """
        if self.parameters is None:
            if params:
                raise InputError(
                    f"model '{self.label}' was trained on one structure: it takes no params "
                    "(fit it with each training record's params to make a model of a family)"
                )
            return None
        return self.parameters.values(params, n, self._nominal())

    def _nominal(self) -> dict[str, float]:
        """Parameter path -> the value of the model's own structure (none without one)."""
        if self.structure is None:
            return {}
        table = self.structure.get_params()
        return {name: value_at(table, name) for name in self.parameters.names}

    def _channels(self, values: np.ndarray | None) -> np.ndarray | None:
        """``[n, k]`` the standardised parameter input channels, or None for a model
        without them."""
        if values is None or not self.formulation.parameter_input:
            return None
        return self.parameters.encode(values)

    def _inputs(
        self,
        motions: GroundMotions,
        z: np.ndarray | None,
        channels: np.ndarray | None = None,
    ) -> np.ndarray:
        """Operator input ``[n, T, channels]``: ``[a_g, t]`` for the baseline, ``[z, t]``
        for a C-Phys model, ``[z, a_g, t]`` with ``formulation.ground_motion_input``; the
        standardised parameter ``channels [n, k]``, constant in time, before ``t`` with
        ``formulation.parameter_input``."""
        ag = motions.acceleration[:, :, None]
        if z is not None and z.shape[:2] != ag.shape[:2]:
            raise InputError(f"physics response {z.shape} does not match motions {ag.shape[:2]}")
        channels_in = [ag] if z is None else [z]
        if z is not None and self.formulation.ground_motion_input:
            channels_in.append(ag)
        if channels is not None:
            shape = (*ag.shape[:2], channels.shape[1])
            channels_in.append(np.broadcast_to(channels[:, None, :], shape))
        channels_in.append(np.broadcast_to(motions.time[None, :, None], ag.shape))
        return np.concatenate(channels_in, axis=2)

    def _target(
        self,
        u: np.ndarray,
        z: np.ndarray | None,
        acceleration: np.ndarray | None,
        responses: np.ndarray | None = None,
    ) -> np.ndarray:
        """What the operator learns: ``u``, or ``u - z`` with ``formulation.residual``,
        followed by the absolute accelerations with ``formulation.accelerations`` and the
        named responses ``[n, T, k]`` with ``formulation.responses``."""
        displacement = u - z if self.formulation.residual else u
        return _kinds_stacked(displacement, acceleration, responses)

    def _responses(
        self,
        motions: GroundMotions,
        u: np.ndarray,
        acceleration: np.ndarray | None,
        what: str,
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """The checked displacement targets and, for a model that learns them, the
        accelerations (refused when missing or given to a model that does not)."""
        u = self._check_targets(motions, u, f"{what} u")
        if not self.formulation.accelerations:
            if acceleration is not None:
                raise ConfigError(
                    f"{what} accelerations given to a model that does not learn them: set "
                    "formulation.accelerations = true"
                )
            return u, None
        if acceleration is None:
            raise ConfigError(
                f"formulation.accelerations: give the {what} records' absolute accelerations "
                "([n, T, dof] in m/s^2, the structure's 'absolute_acceleration' channel)"
            )
        acceleration = self._check_targets(motions, acceleration, f"{what} acceleration")
        if acceleration.shape != u.shape:
            raise InputError(
                f"{what} acceleration {acceleration.shape} must have the shape of u {u.shape}"
            )
        return u, acceleration

    def _named_responses(
        self, motions: GroundMotions, responses: Mapping[str, np.ndarray] | None, what: str
    ) -> np.ndarray | None:
        """``[n, T, k]`` the named responses of a model that learns them, in the order of
        :attr:`response_names` (refused when missing, of other names than those, or given
        to a model that does not learn them), else None."""
        if not self.formulation.responses:
            if responses:
                raise ConfigError(
                    f"{what} named responses given to a model that does not learn them: set "
                    "formulation.responses = true"
                )
            return None
        if not responses:
            raise ConfigError(
                f"formulation.responses: give the {what} records' named responses (name -> "
                "[n, T, 1] in its unit, the structure's [structure] responses channels)"
            )
        names = self.response_names
        if set(responses) != set(names):
            raise ConfigError(
                f"{what} named responses {sorted(responses)} are not those the model learns: "
                f"{', '.join(names)}"
            )
        shape = (*motions.acceleration.shape, 1)
        found = []
        for name in names:
            values = np.asarray(responses[name], dtype=np.float64)
            if values.shape != shape:
                raise InputError(
                    f"{what} named response '{name}' must be {list(shape)} ([n_records, "
                    f"n_steps, 1] matching the motions), got {list(values.shape)}"
                )
            if not np.isfinite(values).all():
                raise InputError(f"{what} named response '{name}' holds NaN or Inf")
            found.append(values)
        return np.concatenate(found, axis=2)

    @property
    def response_names(self) -> tuple[str, ...]:
        """The named responses the model learns (``formulation.responses``), in the order of
        its output channels; empty for one that learns none or is not trained."""
        return getattr(self, "response_names_", ())

    def _groups(self, n_outputs: int) -> tuple[int, ...] | None:
        """Channels of each response kind the operator outputs, for the loss: the
        displacements, the accelerations, each named response on its own."""
        kinds = (n_outputs,) * (2 if self.formulation.accelerations else 1)
        kinds += (1,) * len(self.response_names)
        return kinds if len(kinds) > 1 else None

    @property
    def _displacements(self) -> int:
        """How many of the operator's output channels are displacements (the first)."""
        kinds = 2 if self.formulation.accelerations else 1
        return (self.operator_.out_channels - len(self.response_names)) // kinds

    def _build_operator(self, in_channels: int, out_channels: int) -> NeuralOperator:
        spec = self.operator_spec
        return get_registry().create(
            "operator",
            spec.name,
            in_channels=in_channels,
            out_channels=out_channels,
            **spec.params,
        )

    # -- training --------------------------------------------------------------------
    def fit(
        self,
        motions: GroundMotions,
        u: np.ndarray,
        validation: tuple[GroundMotions, np.ndarray],
        *,
        epochs: int | None = None,
        z: np.ndarray | None = None,
        validation_z: np.ndarray | None = None,
        acceleration: np.ndarray | None = None,
        validation_acceleration: np.ndarray | None = None,
        responses: Mapping[str, np.ndarray] | None = None,
        validation_responses: Mapping[str, np.ndarray] | None = None,
        params: ParameterValues | None = None,
        validation_params: ParameterValues | None = None,
        param_units: dict[str, str] | None = None,
        progress: Callable[[EpochReport], None] | None = print_progress,
        checkpoint: str | Path | None = None,
        resume: bool = False,
        refit_physics: bool = True,
        **training: Any,
    ) -> CompositeModel:
        """Train the operator (and the refiner, if any) on ``motions -> u``.

        Args:
            motions: training ground motions ``[n, T]``.
            u: training displacements ``[n, T, dof]`` in m.
            validation: ``(motions, u)`` of the validation split, which picks the epoch.
            epochs: overrides ``training.epochs``; further keywords override other
                :class:`TrainingConfig` fields (``batch_size``, ``learning_rate``, ...).
            z: precomputed physics response of ``motions`` (skips the preprocessor).
            validation_z: precomputed physics response of the validation motions.
            acceleration, validation_acceleration: the absolute accelerations ``[n, T,
                dof]`` (m/s^2) of the training and validation records, for a model that
                learns them (``formulation.accelerations``).
            responses, validation_responses: name -> ``[n, T, 1]`` each named response of
                the training and validation records (in its unit; the same names in both),
                for a model that learns them (``formulation.responses``).
            params, validation_params: for a model of a family of structures, each
                record's values of the structure's random parameters (path -> ``[n]``
                values, in the parameters' units; the same paths in both); they rebuild
                each record's structure for its physics response unless ``z`` is given,
                and enter the operator with ``formulation.parameter_input``.
            param_units: path -> unit label of each parameter, for reports.
            progress: per-epoch callback (None for silence).
            checkpoint: file to write after every epoch (see :func:`train_operator`).
            resume: continue from ``checkpoint`` where an interrupted fit stopped.
            refit_physics: False keeps the preprocessor as it was given, fitted to this
                model's structure already (a run fits each preprocessor once for all the
                models it trains on it: a stick's pushovers, say).
        """
        val_motions, val_u = validation
        u, acceleration = self._responses(motions, u, acceleration, "training")
        val_u, validation_acceleration = self._responses(
            val_motions, val_u, validation_acceleration, "validation"
        )
        self.response_names_ = tuple(responses or ()) if self.formulation.responses else ()
        named = self._named_responses(motions, responses, "training")
        validation_named = self._named_responses(val_motions, validation_responses, "validation")
        overrides = {**training, **({"epochs": epochs} if epochs is not None else {})}
        if overrides:
            self.training = self.training.model_copy(update=overrides)
            TrainingConfig.model_validate(self.training.model_dump())
        self._check_physics_given(z, validation_z)
        values, val_values = self._fit_parameters(
            params, validation_params, param_units, motions.n_records, val_motions.n_records
        )
        if self.preprocessor is not None:
            if refit_physics:
                self.preprocessor.fit(self.structure)
            z = self._physics(motions, values) if z is None else z
            if validation_z is None:
                validation_z = self._physics(val_motions, val_values)
        x_train = self._inputs(motions, z, self._channels(values))
        x_val = self._inputs(val_motions, validation_z, self._channels(val_values))
        target = self._target(u, z, acceleration, named)
        fit_normalizer = Normalizer.fit if self.training.normalize else Normalizer.identity
        self.input_normalizer_ = fit_normalizer(x_train)
        self.output_normalizer_ = fit_normalizer(target)
        self.grid_ = motions.grid
        pga = peak_ground_acceleration(motions.acceleration)
        self.training_pga_ = (float(pga.min()), float(pga.max()))
        torch.manual_seed(self.training.seed)
        if self.operator_ is None:
            self.operator_ = self._build_operator(x_train.shape[2], target.shape[2])
            if self.formulation.residual:
                self.operator_.zero_output_()
        self.history_: TrainingHistory = train_operator(
            self.operator_,
            self.input_normalizer_.encode(x_train),
            target,
            self.input_normalizer_.encode(x_val),
            self._target(val_u, validation_z, validation_acceleration, validation_named),
            self.output_normalizer_,
            self.training,
            progress,
            checkpoint=checkpoint,
            resume=resume,
            groups=self._groups(u.shape[2]),
        )
        val_hat = self._run_operator(x_val, validation_z)
        val_truth = _kinds_stacked(val_u, validation_acceleration, validation_named)
        self.validation_rmse_ = np.sqrt(np.mean((val_hat - val_truth) ** 2, axis=(0, 1)))
        if self.refiner is not None:
            calibration = (
                (x_val, validation_z, val_u)
                if self.refiner.calibration_split == "validation"
                else (x_train, z, u)
            )
            x, z_fit, u_fit = calibration
            rng = np.random.default_rng(self.training.seed)
            u_hat = self._run_operator(x, z_fit)[:, :, : self._displacements]
            self.refiner.fit(z_fit, u_hat, u_fit, rng)
        return self

    def _check_physics_given(self, *given: np.ndarray | None) -> None:
        """Refuse a physics response given to the baseline, which has none: it would be
        taken for the operator's input in place of a_g."""
        if self.preprocessor is None and any(z is not None for z in given):
            raise InputError(
                f"model '{self.label}' has no physics preprocessor: give it no physics "
                "response z (it works on a_g)"
            )

    def _fit_parameters(
        self,
        params: ParameterValues | None,
        validation_params: ParameterValues | None,
        units: dict[str, str] | None,
        n: int,
        n_validation: int,
    ) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Learn the parameters' scale from the training records' ``params``; their
        values ``[n, k]`` and the validation records' (None, None for one structure)."""
        if not params:
            if self.formulation.parameter_input:
                raise ConfigError(
                    "formulation.parameter_input: give each training and validation record's "
                    "structural parameters (params, validation_params)"
                )
            if validation_params:
                raise ConfigError("validation_params given without the training records' params")
            self.parameters_ = None
            return None, None
        if not validation_params or set(validation_params) != set(params):
            raise ConfigError(
                f"give validation_params with the same parameters as params: {', '.join(params)}"
            )
        self.parameters_ = ParameterScale.fit(params, n, units)
        self._nominal()  # every parameter must name a number of the structure's table
        nominal: dict[str, float] = {}
        return (
            self.parameters_.values(params, n, nominal),
            self.parameters_.values(validation_params, n_validation, nominal),
        )

    def refine(
        self,
        refiner: PartLike,
        motions: GroundMotions,
        u: np.ndarray,
        z: np.ndarray | None = None,
        seed: int | None = None,
        params: ParameterValues | None = None,
    ) -> CompositeModel:
        """A copy of this trained model with ``refiner`` fitted on ``(motions, u)``: the
        training split, or the validation split for a refiner whose
        ``calibration_split`` is ``"validation"``; ``params`` as in
        :meth:`predict_stages`."""
        self._check_fitted()
        if self.preprocessor is None:
            raise ConfigError("a refiner works on the physics response z: the baseline has none")
        self._check_grid(motions)
        refined = copy.copy(self)
        refined.refiner = resolve("refiner", refiner)
        values = self._parameter_values(params, motions.n_records)
        z = self._physics(motions, values) if z is None else z
        inputs = self._inputs(motions, z, self._channels(values))
        u_hat = self._run_operator(inputs, z)[:, :, : self._displacements]
        rng = np.random.default_rng(self.training.seed if seed is None else seed)
        refined.refiner.fit(z, u_hat, self._check_targets(motions, u, "u"), rng)
        return refined

    def _check_targets(self, motions: GroundMotions, u: np.ndarray, what: str) -> np.ndarray:
        u = np.asarray(u, dtype=np.float64)
        if u.ndim != 3 or u.shape[:2] != motions.acceleration.shape:
            raise InputError(
                f"{what} must be [n_records, n_steps, dof] matching the motions "
                f"{motions.acceleration.shape}, got {u.shape}"
            )
        if self.structure is not None and u.shape[2] != self.structure.n_outputs:
            raise InputError(
                f"{what} has {u.shape[2]} outputs but structure '{self.structure.name}' has "
                f"{self.structure.n_outputs}"
            )
        if u.shape[0] == 0:
            raise InputError(f"{what} holds no records")
        if not np.isfinite(u).all():
            raise InputError(f"{what} holds NaN or Inf")
        return u

    # -- prediction ------------------------------------------------------------------
    @property
    def device(self) -> torch.device:
        """Where the trained operator's weights are, and so where it predicts."""
        self._check_fitted()
        tensors = itertools.chain(self.operator_.parameters(), self.operator_.buffers())
        first = next(tensors, None)
        return torch.device("cpu") if first is None else first.device

    def to(self, device: str | torch.device) -> CompositeModel:
        """Move the trained operator to ``device`` (e.g. ``"cuda"``, or a
        ``training.device`` setting such as ``"auto"``); predictions then run there and
        come back as NumPy arrays. Returns this model."""
        self._check_fitted()
        if isinstance(device, str):
            device = resolve_device(device)
        self.operator_.to(device)
        return self

    @property
    def grid(self) -> TimeGrid | None:
        """The time grid of the training records (None for a model saved before grids
        were recorded): the operator learned on it, so it predicts on it only."""
        return getattr(self, "grid_", None)

    def _check_grid(self, motions: GroundMotions) -> None:
        if self.grid is not None and not motions.grid.matches(self.grid):
            raise InputError(
                f"model '{self.label}' was trained on records of {self.grid}; these have "
                f"{motions.grid}: bring them to its grid first, e.g. "
                "motions.on_grid(model.grid) (anti-aliased resampling, then cut or "
                "zero-padded at the end; cphysfno predict --on-grid does the same)"
            )

    def _check_fitted(self) -> None:
        if getattr(self, "operator_", None) is None or not hasattr(self, "input_normalizer_"):
            raise NotFittedError(f"model '{self.label}' is not trained: call fit() or load()")

    def _run_operator(self, inputs: np.ndarray, z: np.ndarray | None) -> np.ndarray:
        """The operator's prediction ``û [n, T, channels]`` (float64, m; accelerations in
        m/s^2 after the displacements for a model that learns them) for un-normalised
        ``inputs [n, T, in]`` and physics response ``z``, in chunks of
        :data:`PREDICT_CHUNK` records, in float32."""
        return self._operator_chunks(
            inputs.shape[0], inputs.shape[1], lambda rows: inputs[rows], z, "float32"
        )

    def _operator_chunks(
        self,
        n: int,
        steps: int,
        inputs_of: Callable[[slice], np.ndarray],
        z: np.ndarray | None,
        precision: Precision,
    ) -> np.ndarray:
        """The operator's prediction ``û [n, steps, dof]`` (float64, m), chunk by chunk:
        its decoded output, plus ``z`` with ``formulation.residual``.

        ``inputs_of(rows)`` gives the un-normalised inputs ``[len(rows), steps, in]`` of a
        slice of records, so that no input array larger than a chunk need exist. The
        operator computes in ``precision`` (see :mod:`cphysfno_core.precision`); its output
        is decoded in float32.
        """
        tune_memory()
        out = np.empty((n, steps, self.operator_.out_channels))
        self.operator_.eval()
        device = self.device
        with torch.no_grad(), operator_precision(device, precision):
            for start in range(0, n, PREDICT_CHUNK):
                rows = slice(start, start + PREDICT_CHUNK)
                x = torch.from_numpy(self.input_normalizer_.encode(inputs_of(rows))).to(device)
                y = self.operator_(x).to(x.dtype)
                decoded = self.output_normalizer_.decode_torch(y)
                out[rows] = decoded.cpu().numpy()
                if self.formulation.residual:
                    out[rows, :, : z.shape[2]] += z[rows]
        return out

    def predict_stages(
        self,
        motions: GroundMotions | np.ndarray,
        z: np.ndarray | None = None,
        *,
        params: ParameterValues | None = None,
        precision: Precision = "float32",
        dt: float | None = None,
    ) -> Prediction:
        """Every stage of the prediction for ``motions`` (z may be given precomputed):
        :class:`GroundMotions`, or a NumPy array ``[n, T]`` (or ``[T]``) of ground
        accelerations in m/s^2 with its time step ``dt`` in s.

        A model of a family of structures (see :attr:`parameters`) takes each record's
        structural ``params``: path -> ``[n]`` values (or one value for every record) in
        the parameters' units; a parameter left out takes the value of the model's own
        structure (the distributions' medians in a run). Values outside the training
        draws' range are predicted with an :class:`ExtrapolationWarning`.

        The operator runs on chunks of :data:`PREDICT_CHUNK` records whose inputs are built
        one chunk at a time; beyond the returned arrays, memory use does not grow with the
        number of records. With ``precision="bfloat16"`` it computes under
        ``torch.autocast`` in bfloat16 (about twice as fast on a CPU with native
        bfloat16, at a small accuracy cost: see :mod:`cphysfno_core.precision`); physics,
        normalisers and refiner stay in float64 or float32 as always.

        Raises:
            InputError: ``precision`` is neither ``"float32"`` nor ``"bfloat16"``;
                ``motions`` are neither ground motions nor an array with its ``dt``;
                ``params`` given to a model of one structure, naming a parameter the model
                does not know, or of another length than the records.
        """
        self._check_fitted()
        motions = as_ground_motions(motions, dt)
        self._check_grid(motions)
        warn_extrapolation(motions, getattr(self, "training_pga_", None), self.label)
        values = self._parameter_values(params, motions.n_records)
        if values is not None:
            self.parameters.warn_outside(values, self.label)
        self._check_physics_given(z)
        if self.preprocessor is not None and z is None:
            z = self._physics(motions, values)
        shape = motions.acceleration.shape
        if z is not None and z.shape[:2] != shape:
            raise InputError(f"physics response {z.shape} does not match motions {shape}")
        channels = self._channels(values)
        output = self._operator_chunks(
            shape[0],
            shape[1],
            lambda rows: self._inputs(motions[rows], _rows_of(z, rows), _rows_of(channels, rows)),
            z,
            precision,
        )
        n = self._displacements
        operator_output = np.ascontiguousarray(output[:, :, :n])
        acceleration = None
        if self.formulation.accelerations:
            acceleration = np.ascontiguousarray(output[:, :, n : 2 * n])
        first = output.shape[2] - len(self.response_names)
        responses = {
            name: np.ascontiguousarray(output[:, :, first + j : first + j + 1])
            for j, name in enumerate(self.response_names)
        }
        if self.refiner is not None:
            mean, std = self.refiner.predict(z, operator_output)
        else:
            mean = operator_output
            std = np.broadcast_to(self.validation_rmse_[:n], mean.shape).copy()
        return Prediction(z, operator_output, mean, std, acceleration, responses)

    def predict(
        self,
        motions: GroundMotions | np.ndarray,
        *,
        params: ParameterValues | None = None,
        precision: Precision = "float32",
        dt: float | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Predicted displacement ``(mean, std)``, each ``[n, T, dof]`` in m; ``motions``,
        ``params``, ``precision`` and ``dt`` as in :meth:`predict_stages`."""
        stages = self.predict_stages(motions, params=params, precision=precision, dt=dt)
        return stages.mean, stages.std

    def save(self, directory: str | Path) -> Path:
        """Write the trained model into ``directory`` (see
        :func:`~cphysfno_core.model.persistence.save_model`)."""
        self._check_fitted()
        return save_model(self, directory)

    @classmethod
    def load(cls, directory: str | Path) -> CompositeModel:
        """Rebuild a saved model from its parts' names and parameters; no code is unpickled
        (see :func:`~cphysfno_core.model.persistence.load_model`).

        Raises:
            DatasetError: a tampered, truncated or foreign file.
        """
        return load_model(directory, cls)
