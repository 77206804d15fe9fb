"""Assembling an untrained composite model from parts."""

from __future__ import annotations

from typing import Any

from ..api.interfaces import NeuralOperator, validate_params
from ..api.registry import get_registry
from ..config.experiment import ComponentSpec, FormulationConfig, TrainingConfig
from .composite import CompositeModel
from .parts import PartLike, as_spec, resolve


def compose(
    *,
    operator: PartLike,
    structure: PartLike | None = None,
    preprocessor: PartLike | None = None,
    refiner: PartLike | None = None,
    training: TrainingConfig | dict[str, Any] | None = None,
    formulation: FormulationConfig | dict[str, Any] | None = None,
) -> CompositeModel:
    """Assemble an untrained :class:`CompositeModel` from parts given by name,
    ``(name, params)``, or as instances, mixed freely.

    The structure is checked here for the capabilities the preprocessor requires, so a
    missing one fails now, before any simulation or training. ``formulation`` (see
    :class:`FormulationConfig`) chooses a residual target or an extra a_g input channel.
    """
    if isinstance(training, dict):
        training = validate_params(TrainingConfig, training, "training")
    if isinstance(formulation, dict):
        formulation = validate_params(FormulationConfig, formulation, "formulation")
    op = operator if isinstance(operator, NeuralOperator) else as_spec(operator)
    if isinstance(op, ComponentSpec):
        validate_params(get_registry().get("operator", op.name).Params, op.params, "operator")
    return CompositeModel(
        op,
        structure=resolve("structure", structure),
        preprocessor=resolve("preprocessor", preprocessor),
        refiner=resolve("refiner", refiner),
        training=training,
        formulation=formulation,
    )
