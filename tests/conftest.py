import os
import sys
from pathlib import Path

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.api.registry import set_registry
from cphysfno_core.plugin import Registry

sys.path.insert(0, str(Path(__file__).parent))

import toy_components  # noqa: E402


@pytest.fixture
def toy_registry():
    """The process registry replaced by one holding only the toy components."""
    registry = Registry(autoload=False, plugins=(toy_components,))
    set_registry(registry)
    yield registry
    set_registry(None)


@pytest.fixture
def toys_in_workers(toy_registry, monkeypatch):
    """Worker processes load the toy components instead of the installed plugins."""
    monkeypatch.setenv("CPHYSFNO_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.setenv("CPHYSFNO_PLUGINS", "toy_components")
    here = str(Path(__file__).parent)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([here, os.environ.get("PYTHONPATH", "")]))


@pytest.fixture
def toy_records(toy_registry):
    """The toy structure, 12 toy records (80 samples at 0.02 s) and its response to them."""
    source = cp.create("ground_motion", "toy-source", n_steps=80, dt=0.02, scale=0.5)
    structure = cp.create("structure", "toy-structure", cubic=50.0)
    gm = source.sample(12, np.random.default_rng(1))
    return structure, gm, structure.simulate(gm).displacement


@pytest.fixture
def trained_toy(toy_records):
    """A toy C-Phys model with the toy refiner trained one epoch on the first 8 records,
    and the 12 records."""
    structure, gm, u = toy_records
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator="toy-operator",
        refiner="toy-refiner",
    )
    model.fit(gm[:8], u[:8], validation=(gm[8:], u[8:]), epochs=1, progress=None)
    return model, gm
