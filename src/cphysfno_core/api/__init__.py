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
)
from .kinds import KINDS, Kind
from .registry import Registry, create, get_registry

__all__ = [
    "KINDS",
    "Kind",
    "GroundMotionSource",
    "NeuralOperator",
    "Params",
    "PhysicsPreprocessor",
    "Refiner",
    "Registry",
    "RestoringForce",
    "Structure",
    "create",
    "get_registry",
    "hookimpl",
]
