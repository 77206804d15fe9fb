"""The opensees-model examples run end to end through the command line at tiny size: the
SI frame, and the kip-inch frame with its leaning column tied in chains."""

from __future__ import annotations

import json

import numpy as np
import pytest
import script_models as sm

import cphysfno_core as cp
from cphysfno_core.app.cli import main


@pytest.mark.parametrize(
    ("name", "handler"), [("opensees-model", "Transformation"), ("opensees-model-us", "Penalty")]
)
def test_the_example_runs_end_to_end(name, handler, tmp_path):
    config = sm.tiny_example(name, tmp_path)
    out = tmp_path / "out"
    assert main(["-q", "run", str(config), "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["output_names"] == ["floor-1", "roof"]
    assert {"fno", "c-physfno-els", "c-physfno-relaxed", "physics-els"} <= set(metrics["models"])
    for label, row in metrics["models"].items():
        assert np.all(np.isfinite(row["rel_l2"])), label
    assert metrics["edp"] is not None
    dataset = cp.load_dataset(out / "dataset.h5")
    assert dataset.u.shape == (8, 401, 2) and not dataset.failures
    assert np.abs(dataset.u).max() > 1e-3
    structure = cp.load_config(config).structure
    model = cp.create("structure", structure.name, **structure.params)
    assert model.constraints_handler == handler


@pytest.mark.parametrize("name", ["opensees-model", "opensees-model-us"])
def test_the_example_scripts_are_the_models_they_describe(name):
    structure = cp.load_config(sm.EXAMPLES / f"{name}.toml").structure
    model = cp.create("structure", structure.name, **structure.params)
    expected = {"opensees-model": 0.4645, "opensees-model-us": 0.8458}[name]
    assert model.periods()[0] == pytest.approx(expected, rel=1e-3)
    stories = model.stories()
    assert stories.lower == (None, 0) and stories.upper == (0, 1)
