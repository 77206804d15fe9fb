"""A model predicts on the time grid it was trained on: other grids are refused with the
way to bring records onto it, and ``GroundMotions.on_grid`` is that way."""

import json

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.plugin import TimeGrid


def test_the_training_grid_is_kept_and_saved(trained_toy, tmp_path):
    model, gm = trained_toy
    assert model.grid == TimeGrid(0.02, 80)
    loaded = cp.CompositeModel.load(model.save(tmp_path / "m"))
    assert loaded.grid == model.grid
    np.testing.assert_allclose(loaded.predict(gm[8:])[0], model.predict(gm[8:])[0])


@pytest.mark.parametrize(
    ("steps", "dt", "grid"),
    [(100, 0.02, "100 samples at dt = 0.02 s"), (80, 0.01, "80 samples at dt = 0.01 s")],
)
def test_records_on_another_grid_are_refused_with_the_way_out(trained_toy, steps, dt, grid):
    model, _ = trained_toy
    other = cp.GroundMotions(np.ones((2, steps)), dt)
    message = (
        f"trained on records of 80 samples at dt = 0.02 s; these have {grid}: bring them "
        "to its grid first, e.g. motions.on_grid\\(model.grid\\)"
    )
    with pytest.raises(cp.InputError, match=message):
        model.predict(other)
    mean, std = model.predict(other.on_grid(model.grid))
    assert mean.shape == std.shape == (2, 80, 2)


def test_a_model_saved_without_its_grid_still_loads_and_predicts(trained_toy, tmp_path):
    model, gm = trained_toy
    folder = model.save(tmp_path / "old")
    saved = json.loads((folder / "model.json").read_text())
    del saved["grid"]
    (folder / "model.json").write_text(json.dumps(saved))
    old = cp.CompositeModel.load(folder)
    assert old.grid is None
    assert old.predict(gm[8:])[0].shape == (4, 80, 2)


def test_a_malformed_grid_is_refused_at_load(trained_toy, tmp_path):
    model, _ = trained_toy
    folder = model.save(tmp_path / "bad")
    saved = json.loads((folder / "model.json").read_text())
    saved["grid"] = {"dt": -0.01, "n_steps": 80}
    (folder / "model.json").write_text(json.dumps(saved))
    with pytest.raises(cp.DatasetError, match="grid.dt"):
        cp.CompositeModel.load(folder)


def test_on_grid_resamples_without_aliasing_then_pads_or_cuts():
    dt = 0.01
    t = np.arange(2001) * dt
    slow, fast = np.sin(2 * np.pi * 1.0 * t), np.sin(2 * np.pi * 40.0 * t)
    motions = cp.GroundMotions(np.stack([slow, slow + fast]), dt)
    coarse = motions.on_grid(TimeGrid(0.02, 1001))
    t2 = np.arange(1001) * 0.02
    middle = slice(100, 900)  # away from the filter's edge transients
    for row in coarse.acceleration:  # 40 Hz lies above the new 25 Hz Nyquist: removed
        np.testing.assert_allclose(row[middle], np.sin(2 * np.pi * t2[middle]), atol=2e-3)
    padded = motions.on_grid(TimeGrid(0.01, 2501))
    np.testing.assert_array_equal(padded.acceleration[:, :2001], motions.acceleration)
    assert not padded.acceleration[:, 2001:].any()
    cut = motions.on_grid(TimeGrid(0.01, 500))
    np.testing.assert_array_equal(cut.acceleration, motions.acceleration[:, :500])
    assert cut.grid == TimeGrid(0.01, 500)
