"""The DeepONet inside composite models: built by name, saved and loaded, run from a config.

These tests use the built-in white-noise source, Bouc-Wen building, ELS preprocessor and
linear-regression refiner, at tiny sizes.
"""

from __future__ import annotations

import json

import cphysfno_core as cp
import numpy as np
import pytest
from cphysfno_core.app.cli import main

SMALL = dict(sensors=32, latent=8, branch_width=16, trunk_width=16, fourier_features=4)

CONFIG = """
[structure]
name = "bouc-wen-shear-building"

[ground_motion]
name = "white-noise"
duration = 2.0

[[preprocessor]]
name = "els"

[operator]
name = "deeponet"
sensors = 32
latent = 8
branch_width = 16
trunk_width = 16
fourier_features = 4

[refiner]
name = "linear-regression"

[data]
n_train = 8
n_val = 4
n_test = 4
chunk_size = 8
executor = "serial"

[training]
epochs = 2
batch_size = 4

[output]
figures = false
"""


@pytest.fixture(scope="module")
def records() -> tuple[cp.GroundMotions, np.ndarray]:
    """12 white-noise records of 2 s and the Bouc-Wen floor displacements (m)."""
    motions = cp.create("ground_motion", "white-noise", duration=2.0).sample(
        12, np.random.default_rng(0)
    )
    return motions, cp.create("structure", "bouc-wen-shear-building").simulate(motions).displacement


def test_save_and_load_reproduce_the_prediction(records, tmp_path) -> None:
    motions, u = records
    model = cp.compose(
        structure="bouc-wen-shear-building",
        preprocessor="els",
        operator=("deeponet", SMALL),
        training={"batch_size": 4},
    )
    model.fit(motions[:6], u[:6], validation=(motions[6:9], u[6:9]), epochs=2, progress=None)
    mean, std = model.predict(motions[9:])
    loaded = cp.CompositeModel.load(model.save(tmp_path / "model"))
    assert loaded.label == "c-physdeeponet-els"
    assert loaded.operator_.get_params() == model.operator_.get_params()
    loaded_mean, loaded_std = loaded.predict(motions[9:])
    np.testing.assert_array_equal(loaded_mean, mean)
    np.testing.assert_array_equal(loaded_std, std)


def test_runs_by_name_from_a_config(tmp_path, capsys) -> None:
    path = tmp_path / "deeponet.toml"
    path.write_text(CONFIG)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    assert "c-physdeeponet-els" in capsys.readouterr().out
    models = json.loads((out / "metrics.json").read_text())["models"]
    assert set(models) == {
        "deeponet",
        "c-physdeeponet-els",
        "refined-c-physdeeponet-els",
        "physics-els",
    }
    for row in models.values():
        assert len(row["rel_l2"]) == 5 and np.isfinite(row["rel_l2"]).all()
    saved = json.loads((out / "models" / "deeponet" / "model.json").read_text())
    assert saved["operator"] == {"name": "deeponet", **SMALL, "in_channels": 2, "out_channels": 5}

    model = cp.CompositeModel.load(out / "models" / "c-physdeeponet-els")
    longer = cp.create("ground_motion", "white-noise", duration=3.0).sample(
        2, np.random.default_rng(1)
    )
    with pytest.raises(cp.InputError, match="trained on records of 201 samples at dt = 0.01"):
        model.predict(longer)  # the trunk would stretch 3 s onto the 2 s it was trained on
    mean, std = model.predict(longer.on_grid(model.grid))
    assert mean.shape == std.shape == (2, 201, 5)
    assert np.isfinite(mean).all()
