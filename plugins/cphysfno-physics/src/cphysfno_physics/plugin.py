"""Entry point of the ``cphysfno-physics`` distribution: registers its preprocessors."""

from __future__ import annotations

from cphysfno_core.plugin import hookimpl

from .els import EquivalentLinear, ExactEquivalentLinear, SecantEquivalentLinear
from .modal import ModalReduction
from .relaxed import RelaxedSolver
from .stick import Stick


@hookimpl
def cphysfno_preprocessors() -> list[type]:
    """The physics preprocessors ``els``, ``els-exact``, ``els-secant``, ``modal``,
    ``relaxed`` and ``stick``."""
    return [
        EquivalentLinear,
        ExactEquivalentLinear,
        SecantEquivalentLinear,
        ModalReduction,
        RelaxedSolver,
        Stick,
    ]
