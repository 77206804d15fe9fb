"""Every check of every component as its own pytest case: :func:`parametrize_with_checks`.

A component is given as what its kind's checks take: an instance of a structure, story
law, ground-motion source or refiner; a neural operator class, or ``(cls, hyper)`` with
the hyperparameters to build it with; a preprocessor with the structure it is checked on,
``(preprocessor, structure)``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable
from typing import Any

from ..api.interfaces import (
    GroundMotionSource,
    NeuralOperator,
    PhysicsPreprocessor,
    Refiner,
    Structure,
)
from ..api.story_law import StoryLaw
from .ground_motion import GROUND_MOTION_CHECKS
from .operator import OPERATOR_CHECKS
from .preprocessor import PREPROCESSOR_CHECKS
from .refiner import REFINER_CHECKS
from .story_law import STORY_LAW_CHECKS
from .structure import structure_checks

_INSTANCE_CHECKS: tuple[tuple[type, Callable[[Any], Iterable[Callable[..., None]]]], ...] = (
    (Structure, structure_checks),
    (StoryLaw, lambda law: STORY_LAW_CHECKS),
    (GroundMotionSource, lambda source: GROUND_MOTION_CHECKS),
    (Refiner, lambda refiner: REFINER_CHECKS),
)
"""The kinds given as an instance, and the checks of an instance of each."""


def _name(component: Any) -> str:
    return getattr(component, "name", None) or type(component).__name__


def _is_operator(candidate: Any) -> bool:
    return isinstance(candidate, type) and issubclass(candidate, NeuralOperator)


def _resolved(component: Any) -> tuple[Any, Iterable[Callable[..., None]], dict[str, Any], str]:
    """``(subject, checks, what the checks take besides the subject, name)``."""
    if isinstance(component, tuple) and len(component) == 2:
        subject, extra = component
        if isinstance(subject, PhysicsPreprocessor) and isinstance(extra, Structure):
            name = f"{_name(subject)}-on-{_name(extra)}"
            return subject, PREPROCESSOR_CHECKS, {"structure": extra}, name
        if _is_operator(subject) and isinstance(extra, dict):
            return subject, OPERATOR_CHECKS, extra, subject.name
    elif _is_operator(component):
        return component, OPERATOR_CHECKS, {}, component.name
    else:
        for base, checks_of in _INSTANCE_CHECKS:
            if isinstance(component, base):
                return component, checks_of(component), {}, _name(component)
    raise TypeError(
        f"{component!r} is not a component to check: give a structure, story law, "
        "ground-motion source or refiner instance, a neural operator class or (class, "
        "hyperparameters), or (preprocessor, structure)"
    )


def component_checks(component: Any) -> list[tuple[Any, Callable[[Any], None], str]]:
    """``(subject, check, id)`` for each check of ``component`` (given as the module doc
    says), in order: ``check(subject)`` runs the check, raising ``AssertionError`` where
    the component breaks its contract; ``id`` is ``"<name>-<check>"``, the name of a
    preprocessor ``"<preprocessor>-on-<structure>"``.

    Raises:
        TypeError: ``component`` is none of the kinds.
    """
    subject, checks, extra, name = _resolved(component)
    return [
        (subject, functools.partial(check, **extra) if extra else check, f"{name}-{check.__name__}")
        for check in checks
    ]


def parametrize_with_checks(components: Iterable[Any]) -> Any:
    """A ``pytest.mark.parametrize`` of a test over ``(component, check)``: one case for
    each check of each component, with ids such as ``shear-building-check_simulate_shape``.
    The test runs the check::

        from cphysfno_core.testing import parametrize_with_checks

        @parametrize_with_checks([MyBuilding(), (MyPreprocessor(), MyBuilding())])
        def test_conforms(component, check):
            check(component)

    Args:
        components: instances of structures, story laws, ground-motion sources and
            refiners; neural operator classes, or ``(cls, hyper)``; ``(preprocessor,
            structure)`` pairs (the checks of a pair share one fit of the preprocessor).

    Raises:
        TypeError: one of ``components`` is none of the kinds.
    """
    import pytest  # a test dependency, not one of the package

    cases = [case for component in components for case in component_checks(component)]
    return pytest.mark.parametrize(
        "component, check",
        [pytest.param(subject, check, id=case_id) for subject, check, case_id in cases],
    )
