"""The composite model: composition of the parts, training, prediction and persistence."""

from .assembly import compose
from .composite import CompositeModel, Prediction
from .labels import ModelLabel

__all__ = ["CompositeModel", "ModelLabel", "Prediction", "compose"]
