"""The composite model: composition of the parts, training, prediction and persistence."""

from .assembly import compose
from .composite import CompositeModel, Prediction
from .parts import model_label

__all__ = ["CompositeModel", "Prediction", "compose", "model_label"]
