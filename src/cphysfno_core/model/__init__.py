"""The composite model: composition of the parts, training, prediction and persistence."""

from .composite import CompositeModel, Prediction, compose, model_label

__all__ = ["CompositeModel", "Prediction", "compose", "model_label"]
