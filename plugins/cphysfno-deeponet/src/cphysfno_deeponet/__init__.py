"""Deep operator network (Lu et al., 2021) for cphysfno, registered as operator ``deeponet``."""

from .encoding import fourier_features, relative_time, resample_to_sensors
from .model import DeepONet, DeepONetParams

__all__ = ["DeepONet", "DeepONetParams", "fourier_features", "relative_time", "resample_to_sensors"]
