"""cphysfno: composite physics-neural operators for seismic response prediction.

The package is layered; each subpackage imports only those below it:

- :mod:`~cphysfno_core.app`: the pipeline of a run, studies, the command line;
- :mod:`~cphysfno_core.reporting`: metrics, figures, ``report.md``;
- :mod:`~cphysfno_core.data` and :mod:`~cphysfno_core.model`: datasets and their
  generation; the composite model, its training, prediction and persistence;
- :mod:`~cphysfno_core.config` and :mod:`~cphysfno_core.testing`: the experiment's
  configuration; the conformance checks for plugin authors;
- :mod:`~cphysfno_core.api`: the component interfaces, hooks and registry;
- :mod:`~cphysfno_core.signals`: time histories, errors, linear systems, intensity measures.

The names below are the public API; plugins import only these (or
:mod:`cphysfno_core.signals` and :mod:`cphysfno_core.testing`).
"""

from . import edp
from .api import (
    GroundMotionSource,
    LawFunctions,
    NeuralOperator,
    Params,
    PhysicsPreprocessor,
    Refiner,
    Registry,
    RestoringForce,
    StoryLaw,
    Structure,
    create,
    get_registry,
    hookimpl,
    per_story,
    validate_params,
)
from .config import (
    ComponentSpec,
    ExperimentConfig,
    FormulationConfig,
    TrainingConfig,
    load_config,
    native_bfloat16,
    parse_config,
)
from .data import Dataset, generate_dataset, load_dataset
from .model import CompositeModel, Prediction, compose
from .reporting import metrics
from .reporting.figures import motion_spectra
from .signals import (
    CapabilityError,
    ConfigError,
    CphysfnoError,
    CphysfnoWarning,
    DatasetError,
    ExtrapolationWarning,
    GroundMotions,
    InputError,
    LinearSystem,
    MainGuardError,
    NotFittedError,
    PluginError,
    Rayleigh,
    RegistryError,
    Responses,
    Stories,
    StoryPushover,
    TimeGrid,
    check_finite,
    check_main_guard,
    check_time_step,
    intensity,
    resampling,
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
    "edp",
    "generate_dataset",
    "intensity",
    "load_config",
    "load_dataset",
    "metrics",
    "motion_spectra",
    "native_bfloat16",
    "parse_config",
    "resampling",
    "CapabilityError",
    "ConfigError",
    "CphysfnoError",
    "CphysfnoWarning",
    "ExtrapolationWarning",
    "DatasetError",
    "GroundMotionSource",
    "GroundMotions",
    "InputError",
    "LawFunctions",
    "LinearSystem",
    "MainGuardError",
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
    "Stories",
    "StoryLaw",
    "StoryPushover",
    "Structure",
    "TimeGrid",
    "check_finite",
    "check_main_guard",
    "check_time_step",
    "create",
    "get_registry",
    "hookimpl",
    "per_story",
    "validate_params",
]
