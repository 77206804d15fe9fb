"""Records to simulated datasets: generation in chunks on local processes or Dask, the
HDF5 dataset, splits, and the layout of a run's output folder."""

from .datasets import SPLITS, Dataset, load_dataset
from .generation import generate_dataset

__all__ = ["SPLITS", "Dataset", "generate_dataset", "load_dataset"]
