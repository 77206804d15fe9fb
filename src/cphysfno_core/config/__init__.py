"""The experiment's configuration (one TOML file, validated before any work) and the
arithmetic precision of the operator."""

from .experiment import (
    ComponentSpec,
    DataConfig,
    ExperimentConfig,
    FormulationConfig,
    OutputConfig,
    StudyConfig,
    SweepConfig,
    TrainingConfig,
    check_components,
    load_config,
    parse_config,
)
from .precision import PRECISIONS, Precision, native_bfloat16, operator_precision

__all__ = [
    "PRECISIONS",
    "ComponentSpec",
    "DataConfig",
    "ExperimentConfig",
    "FormulationConfig",
    "OutputConfig",
    "Precision",
    "StudyConfig",
    "SweepConfig",
    "TrainingConfig",
    "check_components",
    "load_config",
    "native_bfloat16",
    "operator_precision",
    "parse_config",
]
