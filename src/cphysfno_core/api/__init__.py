"""What a plugin author implements and registers: the component interfaces, the hook
specifications and the registry. Imports only :mod:`cphysfno_core.signals`."""

from .hookspecs import hookimpl
from .interfaces import (
    GroundMotionSource,
    NeuralOperator,
    Params,
    PhysicsPreprocessor,
    Refiner,
    RestoringForce,
    Structure,
    validate_params,
)
from .kinds import KINDS, Kind
from .registry import Registry, create, get_registry
from .story_law import LawFunctions, StoryLaw, per_story

__all__ = [
    "KINDS",
    "Kind",
    "LawFunctions",
    "GroundMotionSource",
    "NeuralOperator",
    "Params",
    "PhysicsPreprocessor",
    "Refiner",
    "Registry",
    "RestoringForce",
    "StoryLaw",
    "Structure",
    "create",
    "get_registry",
    "hookimpl",
    "per_story",
    "validate_params",
]
