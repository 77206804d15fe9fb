"""The built-in story laws: ``linear``, ``bilinear``, ``bouc-wen`` and ``peak-oriented``."""

from .bilinear import BilinearLaw
from .bouc_wen import BoucWenLaw
from .linear import LinearLaw
from .peak_oriented import PeakOrientedLaw

BUILT_IN_LAWS = (LinearLaw, BilinearLaw, BoucWenLaw, PeakOrientedLaw)

__all__ = ["BUILT_IN_LAWS", "BilinearLaw", "BoucWenLaw", "LinearLaw", "PeakOrientedLaw"]
