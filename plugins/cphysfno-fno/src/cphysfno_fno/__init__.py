"""One-dimensional Fourier neural operator for cphysfno, registered as operator ``fno``."""

from .model import FNO1d, FNOParams, FourierLayer
from .spectral import SpectralConv1d

__all__ = ["FNO1d", "FNOParams", "FourierLayer", "SpectralConv1d"]
