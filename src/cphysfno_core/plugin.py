"""The API for plugin authors: what a component implements, registers and is checked by.

A plugin subclasses one of the component base classes (:class:`Structure`,
:class:`GroundMotionSource`, :class:`PhysicsPreprocessor`, :class:`NeuralOperator`,
:class:`Refiner`, :class:`StoryLaw`), declares its parameters as a :class:`Params`
model, registers the class from a :data:`hookimpl` and tests it with
:func:`parametrize_with_checks` or the ``check_<kind>`` functions of
:mod:`cphysfno_core.testing`::

    from cphysfno_core import ConfigError, GroundMotions, Responses
    from cphysfno_core.plugin import Params, Structure, hookimpl

What a plugin shares with the package's users (``GroundMotions``, ``Responses``,
``create``, the errors) it imports from :mod:`cphysfno_core`; the rest of the bottom
layer (intensity measures, resampling, pushover protocols) is in
:mod:`cphysfno_core.signals`.
"""

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
    get_registry,
    hookimpl,
    per_story,
    validate_params,
)
from .config import native_bfloat16
from .reporting.figures import motion_spectra
from .signals import (
    LinearSystem,
    Rayleigh,
    ResponseChannel,
    Stories,
    StoryPushover,
    TimeGrid,
    check_finite,
    check_main_guard,
    check_time_step,
)
from .testing import parametrize_with_checks

__all__ = [
    # The component base classes and what they are built from.
    "GroundMotionSource", "NeuralOperator", "PhysicsPreprocessor", "Refiner", "StoryLaw",
    "Structure", "RestoringForce", "LawFunctions", "Params", "per_story", "validate_params",
    # Registration.
    "Registry", "get_registry", "hookimpl",
    # What components take, return and check.
    "LinearSystem", "Rayleigh", "ResponseChannel", "Stories", "StoryPushover", "TimeGrid",
    "check_finite", "check_main_guard", "check_time_step", "motion_spectra", "native_bfloat16",
    # The conformance checks, one pytest case each (the checks: cphysfno_core.testing).
    "parametrize_with_checks",
]
