"""Physics preprocessors H_p of cphysfno: equivalent linear system (``els``), modal reduction
(``modal``) and relaxed solver (``relaxed``). The exact linear solver they share is
:func:`cphysfno_physics.linear_response.linear_response`."""

from .els import EquivalentLinear
from .modal import ModalReduction
from .relaxed import RelaxedSolver

__all__ = ["EquivalentLinear", "ModalReduction", "RelaxedSolver"]
