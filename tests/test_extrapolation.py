"""Records far outside the training records' PGA range are predicted with a warning that
says so, and records given in g instead of m/s^2 are named as such."""

import json
import warnings

import numpy as np
import pytest

import cphysfno_core as cp


def _scaled(gm, factor):
    return cp.GroundMotions(gm.acceleration * factor, gm.dt)


def test_records_like_the_training_ones_raise_no_warning(trained_toy):
    model, gm = trained_toy
    low, high = model.training_pga_
    pga = np.abs(gm[:8].acceleration).max(axis=1)
    assert (low, high) == (pga.min(), pga.max())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model.predict(gm[8:])
        model.predict(_scaled(gm[:8], 2.9))  # the strongest stays within 3x the range


def test_far_stronger_records_are_flagged_as_extrapolations(trained_toy):
    model, gm = trained_toy
    mixed = cp.GroundMotions(
        np.concatenate([gm[8:].acceleration, 10.0 * gm[8:10].acceleration]), gm.dt
    )
    with pytest.warns(cp.ExtrapolationWarning, match="2 of 6 records have a PGA outside") as w:
        mean, _ = model.predict(mixed)
    assert "are they in g" not in str(w[0].message)
    assert mean.shape == (6, 80, 2)


def test_records_in_g_are_named(trained_toy):
    model, gm = trained_toy
    with pytest.warns(cp.ExtrapolationWarning, match="are they in g\\?"):
        model.predict(_scaled(gm[8:], 1.0 / 9.80665))


def test_the_range_is_saved_with_the_model(trained_toy, tmp_path):
    model, gm = trained_toy
    folder = model.save(tmp_path / "m")
    assert cp.CompositeModel.load(folder).training_pga_ == pytest.approx(model.training_pga_)
    saved = json.loads((folder / "model.json").read_text())
    del saved["training_pga"]
    (folder / "model.json").write_text(json.dumps(saved))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cp.CompositeModel.load(folder).predict(_scaled(gm[8:], 10.0))


def test_a_wide_training_range_does_not_ask_about_g_for_a_few_strong_records():
    """Trained on PGAs from 0.004 to 17 m/s^2 (every record is inside that range divided by
    g too), a set whose median lies in the range is not suspected of being in g."""
    from cphysfno_core.model.extrapolation import warn_extrapolation

    peaks = np.array([0.2, 1.0, 3.0, 60.0])
    motions = cp.GroundMotions(peaks[:, None] * np.array([[0.0, 1.0, -0.5]]), 0.01)
    with pytest.warns(cp.ExtrapolationWarning, match="1 of 4 records") as w:
        warn_extrapolation(motions, (0.004, 17.0), "m")
    assert "are they in g" not in str(w[0].message)
