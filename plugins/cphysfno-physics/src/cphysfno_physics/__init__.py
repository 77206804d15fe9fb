"""Physics preprocessors H_p of cphysfno: equivalent linear system (``els``), modal reduction
(``modal``), relaxed solver (``relaxed``) and nonlinear stick (``stick``). The exact linear
solver the first two share is :func:`cphysfno_physics.linear_response.linear_response`."""

from .els import EquivalentLinear
from .modal import ModalReduction
from .relaxed import RelaxedSolver
from .stick import Stick
from .stick_calibration import StickCalibration

__all__ = ["EquivalentLinear", "ModalReduction", "RelaxedSolver", "Stick", "StickCalibration"]
