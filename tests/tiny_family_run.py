"""The smallest run of a family of structures: two seconds of white noise, a one-layer FNO
trained one epoch on 6 records, 3 for validation."""

import tomllib

import cphysfno_core as cp
from cphysfno_core.config import ExperimentConfig

REST = """
[ground_motion]
name = "white-noise"
duration = 2.0

[operator]
name = "fno"
layers = 1
modes = 4
width = 6

[training]
epochs = 1
batch_size = 4

[data]
n_train = 6
n_val = 3
n_test = {n_test}
executor = "serial"
"""


def tiny_config(head: str, n_test: int = 3) -> ExperimentConfig:
    """The config of ``head`` (the structure, its preprocessor and any other section) with
    the rest of the tiny run."""
    return cp.parse_config(tomllib.loads(head + REST.format(n_test=n_test)))
