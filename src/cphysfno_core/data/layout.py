"""The layout of a run's output folder."""

DATASET = "dataset.h5"
"""The simulated records, with every physics response (see :mod:`.datasets`)."""

MODELS = "models"
"""The folder of trained models, one ``models/<label>/`` each."""
