"""The built-in story laws: ``linear``, ``bilinear``, ``bouc-wen``, ``peak-oriented`` and
``pinching``."""

from .bilinear import BilinearLaw
from .bouc_wen import BoucWenLaw
from .linear import LinearLaw
from .peak_oriented import PeakOrientedLaw
from .pinching import PinchingLaw

BUILT_IN_LAWS = (LinearLaw, BilinearLaw, BoucWenLaw, PeakOrientedLaw, PinchingLaw)

__all__ = [
    "BUILT_IN_LAWS",
    "BilinearLaw",
    "BoucWenLaw",
    "LinearLaw",
    "PeakOrientedLaw",
    "PinchingLaw",
]
