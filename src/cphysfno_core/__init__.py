"""cphysfno: composite physics-neural operators for seismic response prediction."""

from .composite import CompositeModel, Prediction, compose
from .config import (
    ComponentSpec,
    ExperimentConfig,
    FormulationConfig,
    TrainingConfig,
    load_config,
    parse_config,
)
from .data import Dataset, load_dataset
from .errors import (
    CapabilityError,
    ConfigError,
    CphysfnoError,
    CphysfnoWarning,
    DatasetError,
    ExtrapolationWarning,
    InputError,
    NotFittedError,
    PluginError,
    RegistryError,
)
from .generation import generate_dataset
from .hookspecs import hookimpl
from .interfaces import (
    GroundMotionSource,
    NeuralOperator,
    Params,
    PhysicsPreprocessor,
    Refiner,
    RestoringForce,
    Structure,
)
from .registry import Registry, create, get_registry
from .signals import (
    GroundMotions,
    LinearSystem,
    Rayleigh,
    Responses,
    TimeGrid,
    check_finite,
    check_time_step,
)

__version__ = "0.1.0"

__all__ = [
    "ComponentSpec",
    "CompositeModel",
    "Dataset",
    "ExperimentConfig",
    "Prediction",
    "FormulationConfig",
    "TrainingConfig",
    "compose",
    "generate_dataset",
    "load_config",
    "load_dataset",
    "parse_config",
    "CapabilityError",
    "ConfigError",
    "CphysfnoError",
    "CphysfnoWarning",
    "ExtrapolationWarning",
    "DatasetError",
    "GroundMotionSource",
    "GroundMotions",
    "InputError",
    "LinearSystem",
    "NeuralOperator",
    "NotFittedError",
    "PluginError",
    "Params",
    "PhysicsPreprocessor",
    "Rayleigh",
    "Refiner",
    "Registry",
    "RegistryError",
    "Responses",
    "RestoringForce",
    "Structure",
    "TimeGrid",
    "check_finite",
    "check_time_step",
    "create",
    "get_registry",
    "hookimpl",
]
