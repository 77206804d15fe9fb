"""Drift ratios of a family whose story heights are drawn: each record's drifts over its own
structure's heights, in the EDPs, the drift bounds, a run's error tables and the pelicun
demands."""

import numpy as np
import pytest
from tiny_family_run import tiny_config

import cphysfno_core as cp
from cphysfno_core import edp
from cphysfno_core.api.registry import get_registry
from cphysfno_core.data.record_stories import RecordStories
from cphysfno_core.signals import GroundMotions, Stories


def _records(n=4, steps=60, outputs=3, seed=0):
    rng = np.random.default_rng(seed)
    u = np.cumsum(rng.normal(size=(n, steps, outputs)), axis=1) * 1e-3
    return u, GroundMotions(rng.normal(size=(n, steps)), 0.01)


def test_each_records_heights_give_the_edps_of_that_record_alone():
    u, motions = _records()
    heights = np.array([[3.0, 3.5, 4.0], [2.5, 3.0, 3.0], [4.0, 4.0, 4.0], [3.2, 2.8, 3.6]])
    nominal = Stories.stacked((3.0, 3.0, 3.0))
    together = edp.compute(u, nominal, motions, heights=heights)
    for i in range(u.shape[0]):
        alone = edp.compute(u[i : i + 1], Stories.stacked(tuple(heights[i])), motions[i : i + 1])
        for name in ("PID", "RID", "PFA", "PD"):
            np.testing.assert_allclose(together[name][i], alone[name][0], rtol=1e-14)
    drift = np.abs(np.diff(u, axis=2, prepend=0.0)).max(axis=1)
    np.testing.assert_allclose(together.pid, drift / heights, rtol=1e-14)


def test_drift_bounds_follow_each_records_heights():
    u, motions = _records(seed=1)
    heights = np.array([[3.0, 3.5, 4.0], [2.5, 3.0, 3.0], [4.0, 4.0, 4.0], [3.2, 2.8, 3.6]])
    nominal = Stories.stacked((3.0, 3.0, 3.0))
    together = edp.interval(u, np.full_like(u, 1e-4), nominal, motions, heights=heights)
    for i in range(u.shape[0]):
        alone = edp.interval(
            u[i : i + 1], np.full((1, *u.shape[1:]), 1e-4), Stories.stacked(tuple(heights[i])),
            motions[i : i + 1],
        )  # fmt: skip
        np.testing.assert_allclose(together.pid_upper[i], alone.pid_upper[0], rtol=1e-14)
        np.testing.assert_allclose(together.rid_lower[i], alone.rid_lower[0], rtol=1e-14)


@pytest.mark.parametrize(
    ("heights", "message"),
    [
        (np.full((4, 2), 3.0), r"shape \(4, 2\).*\[4, 3\]"),
        (np.array([[3.0, 3.0, 0.0]] * 4), r"record 0's height of story 3 is 0.0"),
        (np.array([[3.0, np.nan, 3.0]] * 4), r"record 0's height of story 2 is nan"),
    ],
)
def test_heights_that_do_not_fit_the_records_and_stories_are_named(heights, message):
    u, motions = _records()
    with pytest.raises(cp.InputError, match=message):
        edp.compute(u, Stories.stacked((3.0, 3.0, 3.0)), motions, heights=heights)


def test_a_story_without_height_keeps_none_in_every_record():
    u, motions = _records(outputs=2)
    stories = Stories((None, 0), (0, 1), (float("nan"), 3.0))
    heights = np.array([[np.nan, 3.0], [np.nan, 4.0], [np.nan, 2.0], [np.nan, 3.0]])
    found = edp.compute(u, stories, motions, heights=heights)
    np.testing.assert_allclose(found.pid[:, 0], np.abs(u[:, :, 0]).max(axis=1), rtol=1e-14)
    with pytest.raises(cp.InputError, match="story 1 is 3.0"):
        edp.compute(u, stories, motions, heights=np.full((4, 2), 3.0))


def _building(**changes):
    params = {
        "masses": [4.0e4, 3.0e4, 3.0e4],
        "stiffnesses": [4e7, 3e7, 2e7],
        "story_heights": [3.0, 3.5, 3.0],
        "story_law": {"name": "bilinear", "alpha": 0.05, "yield_displacement": 0.02},
    }
    params.update(changes)
    return get_registry().create("structure", "shear-building", **params)


def test_record_stories_find_the_parameters_that_move_the_heights():
    family = RecordStories(_building())
    stiffness = {"stiffnesses.0": np.array([3e7, 4e7, 5e7])}
    assert family.heights(stiffness, 3) is None
    assert family.heights(None, 3) is None
    drawn = {**stiffness, "story_heights.1": np.array([3.5, 4.0, 3.0])}
    found = family.heights(drawn, 3)
    expected = [[3.0, 3.5, 3.0], [3.0, 4.0, 3.0], [3.0, 3.0, 3.0]]
    np.testing.assert_array_equal(found, expected)
    for row, height in zip(found, drawn["story_heights.1"], strict=True):
        heights = list(_building().get_params()["story_heights"])
        heights[1] = height
        assert tuple(row) == _building(story_heights=heights).stories().heights_m


def test_a_first_call_at_the_nominal_value_decides_nothing():
    family = RecordStories(_building())
    assert family.heights({"story_heights.1": np.array([3.5, 3.5])}, 2) is None
    found = family.heights({"story_heights.1": np.array([3.5, 4.5])}, 2)
    np.testing.assert_array_equal(found, [[3.0, 3.5, 3.0], [3.0, 4.5, 3.0]])


def test_every_story_height_drawn_as_one_number_moves_every_story():
    family = RecordStories(_building(story_heights=3.0))
    found = family.heights({"story_heights": np.array([2.5, 4.0])}, 2)
    np.testing.assert_array_equal(found, [[2.5] * 3, [4.0] * 3])


RUN = """
preprocessor = { name = "els" }

[structure]
name = "shear-building"
masses = [4.0e4, 3.0e4]
stiffnesses = [4e7, 3e7]
story_law = { name = "bilinear", alpha = 0.05, yield_displacement = 0.01 }
story_heights = [{ dist = "uniform", low = 2.5, high = 4.5, unit = "m" }, 3.0]

"""


@pytest.fixture(scope="module")
def run_of_drawn_heights(tmp_path_factory):
    from cphysfno_core.app import pipeline

    folder = tmp_path_factory.mktemp("drawn-heights")
    return folder, pipeline.run(tiny_config(RUN, n_test=4), folder)


def _drift_ratios(u, heights):
    return np.abs(np.diff(u, axis=2, prepend=0.0)).max(axis=1) / heights


def test_a_run_scores_each_record_by_its_own_heights(run_of_drawn_heights):
    folder, evaluation = run_of_drawn_heights
    data = cp.load_dataset(folder / "dataset.h5")
    first = data.parameter_draws("test")["story_heights.0"]
    assert np.ptp(first) > 0.1
    heights = np.column_stack([first, np.full_like(first, 3.0)])
    np.testing.assert_allclose(
        evaluation.true_edps.pid, _drift_ratios(data.targets("test"), heights), rtol=1e-12
    )
    els = evaluation.predicted_edps["physics-els"]
    np.testing.assert_allclose(
        els.pid, _drift_ratios(data.physics("els", "test"), heights), rtol=1e-12
    )


def test_demands_of_drawn_heights_are_each_records_drift_ratios(run_of_drawn_heights, tmp_path):
    from cphysfno_core.app.demand_sample import write_demand_sample
    from cphysfno_core.model.skipping import predict_skipping_failures

    folder, _ = run_of_drawn_heights
    write_demand_sample(folder, model_label="c-physfno-els", out=tmp_path / "d.csv")
    data = cp.load_dataset(folder / "dataset.h5")
    model = cp.CompositeModel.load(folder / "models" / "c-physfno-els")
    responses, _ = predict_skipping_failures(model, data.motions("test"))
    first = data.parameter_draws("test")["story_heights.0"]
    heights = np.column_stack([first, np.full_like(first, 3.0)])
    table = np.genfromtxt(tmp_path / "d.csv", delimiter=",", skip_header=2)
    columns = (tmp_path / "d.csv").read_text().splitlines()[0].split(",")
    pid = columns.index("1-PID-1-1")
    np.testing.assert_allclose(
        table[:, pid : pid + 2], _drift_ratios(responses.displacement, heights), rtol=1e-6
    )
