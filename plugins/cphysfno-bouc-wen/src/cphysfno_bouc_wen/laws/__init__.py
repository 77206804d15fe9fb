"""The built-in story laws: ``linear``, ``bilinear``, ``bouc-wen``, ``peak-oriented``,
``pinching`` and ``cracked-pinching``."""

from .bilinear import BilinearLaw
from .bouc_wen import BoucWenLaw
from .cracked_pinching import CrackedPinchingLaw
from .linear import LinearLaw
from .peak_oriented import PeakOrientedLaw
from .pinching import PinchingLaw

BUILT_IN_LAWS = (
    LinearLaw,
    BilinearLaw,
    BoucWenLaw,
    PeakOrientedLaw,
    PinchingLaw,
    CrackedPinchingLaw,
)

__all__ = [
    "BUILT_IN_LAWS",
    "BilinearLaw",
    "BoucWenLaw",
    "CrackedPinchingLaw",
    "LinearLaw",
    "PeakOrientedLaw",
    "PinchingLaw",
]
