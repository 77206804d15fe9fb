"""A shear building of zeroLength springs, every node at the ground's elevation: its stories
have no height, and it still runs end to end, its drifts reported in m; what needs drift
ratios asks for story heights before any work."""

from __future__ import annotations

import json

import numpy as np
import pytest
import script_models as sm

import cphysfno_core as cp
from cphysfno_core import edp
from cphysfno_core.app import pipeline
from cphysfno_core.testing import check_structure

OUTPUTS = [[1, 1], [2, 1], [3, 1]]


@pytest.fixture(scope="module")
def springs(tmp_path_factory):
    """Three stories of Steel01 springs yielding at 0.01 m of drift, 2e4 kg floors; the
    springs take the stiffness part of the Rayleigh damping."""
    stiffness = (4.0e7, 3.0e7, 2.0e7)
    return sm.springs(
        tmp_path_factory.mktemp("springs"), stiffness=stiffness,
        yield_force=tuple(0.01 * k for k in stiffness), masses=(2.0e4,) * 3, rayleigh=True,
    )  # fmt: skip


def test_the_stories_stand_on_each_other_without_heights(springs):
    model = cp.create("structure", "opensees-model", script=str(springs), outputs=OUTPUTS)
    stories = model.stories()
    assert stories.lower == (None, 0, 1) and stories.upper == (0, 1, 2)
    assert np.isnan(stories.heights_m).all() and not stories.has_heights
    check_structure(model)
    motions = sm.records(n=1, n_steps=301, peak=3.0)
    responses = model.simulate(motions)
    u = responses.displacement
    found = edp.compute(responses, model, motions)
    drift = np.diff(np.concatenate([np.zeros((1, 301, 1)), u], axis=2), axis=2)
    np.testing.assert_allclose(found.pid[0], np.abs(drift[0]).max(axis=0))  # m, not a ratio
    with pytest.raises(cp.ConfigError, match="story-1, story-2, story-3 of the structure have no"):
        edp.require_heights(stories, "a fragility on pid")
    for name, params in (("stick", {}), ("els", {"stiffness": "secant"})):
        with pytest.raises(cp.ConfigError, match="give the structure story_heights"):
            cp.create("preprocessor", name, **params).fit(model)


def test_a_run_goes_end_to_end_and_fragility_asks_for_heights(springs, tmp_path, capsys):
    from cphysfno_core.app.cli import main

    config = sm.tiny_run({"name": "opensees-model", "script": str(springs), "outputs": OUTPUTS})
    pipeline.run(config, tmp_path)
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert np.isnan(metrics["edp"]["heights_m"]).all()
    report = (tmp_path / "report.md").read_text()
    assert "story-1, story-2, story-3 of `opensees-model` have no height" in report
    command = ["fragility", str(tmp_path), "--records", "4", "--limit-states", "pid=0.01"]
    assert main(command) == 2
    assert "give the structure story_heights or drift_pairs" in capsys.readouterr().err
    assert not (tmp_path / "fragility").exists()


def test_a_node_the_model_lacks_is_reported_before_any_motion_is_drawn(springs, tmp_path, capsys):
    from cphysfno_core.app.cli import main

    path = tmp_path / "missing.toml"
    path.write_text(
        f'[structure]\nname = "opensees-model"\nscript = "{springs}"\n'
        "outputs = [[1, 1], [2, 1], [9, 1]]\n\n"
        '[ground_motion]\nname = "white-noise"\n\n[[preprocessor]]\nname = "relaxed"\n\n'
        '[operator]\nname = "fno"\n'
    )
    assert main(["check", str(path)]) == 2
    assert "has no node 9" in capsys.readouterr().err
    assert main(["generate", str(path), "--out", str(tmp_path / "run")]) == 2
    assert "has no node 9" in capsys.readouterr().err
    assert not (tmp_path / "run" / "dataset.h5").exists()
    assert not any((tmp_path / "run").glob("*parts*"))
