"""cphysfno: composite physics-neural operators for seismic response prediction.

The names below are the users' API: compose a model from registered components, generate
or load a dataset, train, predict and read the errors::

    import cphysfno_core as cp

    model = cp.compose(structure="bouc-wen-shear-building", operator="fno")

Two modules complete it: :mod:`cphysfno_core.edp` (engineering demand parameters of
simulated or predicted responses) and :mod:`cphysfno_core.plugin`, the API for plugin
authors (the component base classes, ``Params``, ``hookimpl``, the story-law helpers and
the conformance checks).

The package is layered; each subpackage imports only those below it, and all of them are
internal:

- :mod:`~cphysfno_core.app`: the pipeline of a run, studies, the command line;
- :mod:`~cphysfno_core.reporting`: metrics, figures, ``report.md``;
- :mod:`~cphysfno_core.data` and :mod:`~cphysfno_core.model`: datasets and their
  generation; the composite model, its training, prediction and persistence;
- :mod:`~cphysfno_core.config` and :mod:`~cphysfno_core.testing`: the experiment's
  configuration; the conformance checks for plugin authors;
- :mod:`~cphysfno_core.api`: the component interfaces, hooks and registry;
- :mod:`~cphysfno_core.signals`: time histories, errors, linear systems, intensity measures.
"""

from . import edp as edp
from .api import create
from .config import load_config, parse_config
from .data import generate_dataset, load_dataset
from .model import CompositeModel, compose
from .signals import (
    CapabilityError,
    ConfigError,
    CphysfnoError,
    CphysfnoWarning,
    DatasetError,
    ExtrapolationWarning,
    GroundMotions,
    InputError,
    MainGuardError,
    NotFittedError,
    PluginError,
    RegistryError,
    Responses,
)

__version__ = "0.1.0"

__all__ = [
    "CompositeModel",
    "GroundMotions",
    "Responses",
    "compose",
    "create",
    "generate_dataset",
    "load_config",
    "load_dataset",
    "parse_config",
    "CapabilityError",
    "ConfigError",
    "CphysfnoError",
    "CphysfnoWarning",
    "DatasetError",
    "ExtrapolationWarning",
    "InputError",
    "MainGuardError",
    "NotFittedError",
    "PluginError",
    "RegistryError",
]
