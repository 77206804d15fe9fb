"""Ground-motion sources for cphysfno."""

from .white_noise import WhiteNoise

__all__ = ["WhiteNoise"]
