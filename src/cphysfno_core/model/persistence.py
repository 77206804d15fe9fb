"""Saving and loading a composite model without pickled code: ``model.json`` (the parts by
registry name and parameters, validated on reading), ``operator.pt`` (tensors only) and
``arrays.npz`` (normalisers, refiner state; read without pickle)."""

from __future__ import annotations

import dataclasses
import json
import pickle
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import numpy as np
import torch
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from ..api.interfaces import format_validation_error
from ..api.registry import get_registry
from ..config.calibration_surface import CalibrationSurface
from ..config.experiment import FormulationConfig, TrainingConfig
from ..signals import TimeGrid
from ..signals.errors import DatasetError, PluginError
from .parameters import ParameterScale
from .training import Normalizer, TrainingHistory

FORMAT = "cphysfno-composite"
FORMAT_VERSION = 1
SAVED_ARRAYS = ("input_mean", "input_std", "output_mean", "output_std", "validation_rmse")
PARAMETERS = "parameters."
"""The prefix of a family model's parameter scale in ``arrays.npz``."""


class SavedGrid(BaseModel):
    """The training records' time grid in ``model.json``."""

    model_config = ConfigDict(extra="forbid")

    dt: float = Field(gt=0)
    n_steps: int = Field(ge=2)


class SavedModel(BaseModel):
    """Schema of ``model.json``: the parts by registry name and parameters."""

    model_config = ConfigDict(extra="forbid")

    format: Literal["cphysfno-composite"]
    format_version: Literal[1]
    label: str
    structure: dict[str, Any] | None
    preprocessor: dict[str, Any] | None
    refiner: dict[str, Any] | None
    operator: dict[str, Any]
    training: dict[str, Any]
    formulation: dict[str, Any] = Field(default_factory=dict)
    history: dict[str, Any] = Field(default_factory=dict)
    grid: SavedGrid | None = None
    training_pga: tuple[float, float] | None = None
    parameters: dict[str, Any] | None = Field(
        None,
        description="a model of a family of structures: the names and units of the "
        "structural parameters it takes (their scale is in arrays.npz)",
    )
    responses: list[str] = Field(
        default_factory=list,
        description="the named responses the operator learns (formulation.responses), in "
        "the order of its output channels",
    )
    calibration_surface: dict[str, Any] | None = Field(
        None,
        description="a model of a family whose preprocessor is fitted from a calibration "
        "surface: the surface (CalibrationSurface.to_dict)",
    )
    providers: dict[str, str] = Field(
        default_factory=dict,
        description="kind -> the distribution (name and version) that provided the part",
    )

    @field_validator("structure", "preprocessor", "refiner", "operator")
    @classmethod
    def _named(cls, spec: dict[str, Any] | None) -> dict[str, Any] | None:
        if spec is not None and not isinstance(spec.get("name"), str):
            raise ValueError("a part needs its registry name")
        return spec


def _spec_of(component: Any) -> dict[str, Any] | None:
    if component is None:
        return None
    return {"name": component.name, **component.get_params()}


def _providers(model: Any) -> dict[str, str]:
    """Kind -> the distribution (``"name version"``) that registered each part of
    ``model``, as the registry knows it."""
    registry = get_registry()
    parts = {
        "structure": model.structure,
        "preprocessor": model.preprocessor,
        "operator": model.operator_,
        "refiner": model.refiner,
    }
    found = {}
    for kind, part in parts.items():
        if part is None:
            continue
        try:
            found[kind] = registry.entry(kind, part.name).distribution
        except LookupError:
            continue
    return found


def _check_channels(model: Any, directory: Path) -> None:
    """Refuse a model whose operator's output channels are not its displacements, its
    accelerations (``formulation.accelerations``) and its named responses."""
    formulation, names = model.formulation, model.response_names
    kinds = 2 if formulation.accelerations else 1
    displacements = model._displacements
    outputs = None if model.structure is None else model.structure.n_outputs
    if (
        bool(names) != formulation.responses
        or displacements <= 0
        or kinds * displacements + len(names) != model.operator_.out_channels
        or (outputs is not None and displacements != outputs)
    ):
        raise DatasetError(
            f"{directory}: the operator's {model.operator_.out_channels} output channels are "
            f"not the model's outputs ({outputs}), accelerations ({formulation.accelerations}) "
            f"and named responses ({list(names)}): a tampered or mismatched model.json"
        )


def save_model(model: Any, directory: str | Path) -> Path:
    """Write ``model.json`` (parts by name and parameters), ``operator.pt`` (tensors
    only) and ``arrays.npz`` (normalisers, refiner state) into ``directory``; for a
    C-Phys model also what the structure shows of itself (e.g. the pushover behind its
    equivalent linear system) into ``directory/structure`` and what its fitted
    preprocessor shows (e.g. a stick's calibration) into ``directory/preprocessor``, for
    the reader only."""
    model._check_fitted()
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    description = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "label": model.label,
        "structure": _spec_of(model.structure),
        "preprocessor": _spec_of(model.preprocessor),
        "refiner": _spec_of(model.refiner),
        "operator": {
            **model.operator_spec.to_dict(),
            "in_channels": model.operator_.in_channels,
            "out_channels": model.operator_.out_channels,
        },
        "training": model.training.model_dump(mode="json"),
        "formulation": model.formulation.model_dump(mode="json"),
        "history": model.history_.to_dict(),
        "grid": None if model.grid is None else dataclasses.asdict(model.grid),
        "training_pga": getattr(model, "training_pga_", None),
        "parameters": None if model.parameters is None else model.parameters.description(),
        "responses": list(model.response_names),
        "calibration_surface": None
        if model.calibration_surface is None
        else model.calibration_surface.to_dict(),
        "providers": _providers(model),
    }
    arrays = {
        "input_mean": model.input_normalizer_.mean,
        "input_std": model.input_normalizer_.std,
        "output_mean": model.output_normalizer_.mean,
        "output_std": model.output_normalizer_.std,
        "validation_rmse": model.validation_rmse_,
    }
    if model.refiner is not None:
        arrays.update({f"refiner.{k}": v for k, v in model.refiner.state_dict().items()})
    if model.parameters is not None:
        arrays.update({f"{PARAMETERS}{k}": v for k, v in model.parameters.arrays().items()})
    torch.save(model.operator_.state_dict(), directory / "operator.pt")
    np.savez(directory / "arrays.npz", **arrays)
    (directory / "model.json").write_text(json.dumps(description, indent=2))
    if model.preprocessor is not None:
        model.structure.write_artifacts(directory / "structure")
        model.preprocessor.write_artifacts(directory / "preprocessor")
    return directory


def load_model(directory: str | Path, factory: Callable[..., Any]) -> Any:
    """Rebuild a saved model from its parts' names and parameters; no code is unpickled.

    ``factory`` builds the model from its parts (the :class:`CompositeModel` constructor's
    arguments); the fitted state is then set on it and its preprocessor fitted to its
    structure again (or restored from what it saved: ``PhysicsPreprocessor.restore``).

    ``model.json`` is validated, the tensors are read with ``weights_only=True`` and the
    arrays without pickle; a tampered, truncated or foreign file raises DatasetError.
    """
    directory = Path(directory)
    try:
        saved = SavedModel.model_validate_json((directory / "model.json").read_text())
    except OSError as error:
        raise DatasetError(f"{directory} holds no readable model.json: {error}") from None
    except ValidationError as error:
        problems = format_validation_error(error)
        raise DatasetError(f"{directory}/model.json is not a {FORMAT} model: {problems}") from None
    registry = get_registry()

    def build(kind: str, spec: dict[str, Any] | None) -> Any:
        if spec is None:
            return None
        spec = dict(spec)
        name = spec.pop("name")
        try:
            cls = registry.get(kind, name)
        except LookupError as error:
            provider = saved.providers.get(kind)
            if provider is None:
                raise
            distribution = provider.split(" ")[0]
            raise PluginError(
                f"{directory} needs the {kind} '{name}' of {provider}, which is not installed "
                f"here: pip install {distribution} (or pip install -e plugins/{distribution} "
                f"from a cphysfno checkout) ({error})"
            ) from None
        return cls(**spec)

    operator = build("operator", saved.operator)
    try:
        state = torch.load(directory / "operator.pt", weights_only=True, map_location="cpu")
        operator.load_state_dict(state)
        with np.load(directory / "arrays.npz", allow_pickle=False) as stored:
            arrays = {key: stored[key] for key in stored.files}
        normalizers = [arrays[key] for key in SAVED_ARRAYS]
    except Exception as error:
        reason = str(error).splitlines()[0] if str(error) else ""
        if isinstance(error, pickle.UnpicklingError):
            reason = "not plain tensors: refused without running it"
        raise DatasetError(
            f"{directory}: cannot load the model's weights ({type(error).__name__}: {reason})"
        ) from None
    model = factory(
        operator,
        structure=build("structure", saved.structure),
        preprocessor=build("preprocessor", saved.preprocessor),
        refiner=build("refiner", saved.refiner),
        training=TrainingConfig.model_validate(saved.training),
        formulation=FormulationConfig.model_validate(saved.formulation),
        calibration_surface=None
        if saved.calibration_surface is None
        else CalibrationSurface.from_dict(saved.calibration_surface),
    )
    input_mean, input_std, output_mean, output_std, validation_rmse = normalizers
    model.input_normalizer_ = Normalizer(input_mean, input_std)
    model.output_normalizer_ = Normalizer(output_mean, output_std)
    model.validation_rmse_ = validation_rmse
    model.history_ = TrainingHistory(**saved.history) if saved.history else TrainingHistory()
    if saved.grid is not None:
        model.grid_ = TimeGrid(saved.grid.dt, saved.grid.n_steps)
    model.training_pga_ = saved.training_pga
    model.response_names_ = tuple(saved.responses)
    _check_channels(model, directory)
    model.parameters_ = None
    if saved.parameters is not None:
        scale = {k[len(PARAMETERS) :]: v for k, v in arrays.items() if k.startswith(PARAMETERS)}
        try:
            model.parameters_ = ParameterScale.restore(saved.parameters, scale)
        except (KeyError, TypeError) as error:
            raise DatasetError(
                f"{directory}: the scale of the model's structural parameters is incomplete "
                f"({error})"
            ) from None
    if model.refiner is not None:
        prefix = "refiner."
        model.refiner.load_state_dict(
            {k[len(prefix) :]: v for k, v in arrays.items() if k.startswith(prefix)}
        )
    if model.preprocessor is not None:
        model.preprocessor.restore(model.structure, directory / "preprocessor")
    operator.eval()
    return model
