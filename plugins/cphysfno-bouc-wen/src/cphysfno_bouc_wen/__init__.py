"""Bouc-Wen hysteretic shear building for cphysfno (paper Example 1, §5.1)."""

from .restoring import BoucWenRestoringForce
from .structure import BoucWenShearBuilding

__all__ = ["BoucWenRestoringForce", "BoucWenShearBuilding"]
