"""EDP accuracy in a run's metrics.json and report.md, for a structure with stories and one
without."""

import json

import numpy as np

import cphysfno_core as cp
from cphysfno_core import edp
from cphysfno_core.app import pipeline
from cphysfno_core.reporting import baselines

CONFIG = """
[structure]
name = "{structure}"
cubic = 40.0

[ground_motion]
name = "toy-source"
n_steps = 80
scale = 0.5

[[preprocessor]]
name = "toy-linear"

[operator]
name = "toy-operator"
width = 4

[refiner]
name = "toy-refiner"

[data]
n_train = 8
n_val = 4
n_test = 6
chunk_size = 9
executor = "serial"

[training]
epochs = 2
batch_size = 4

[output]
figures = {figures}
"""


def _run(tmp_path, structure, figures="true"):
    path = tmp_path / f"{structure}.toml"
    path.write_text(CONFIG.format(structure=structure, figures=figures))
    out = tmp_path / structure
    return out, pipeline.run(cp.load_config(path), out)


def test_a_run_reports_each_models_edp_errors_and_the_drift_scatter(toy_registry, tmp_path):
    out, evaluation = _run(tmp_path, "toy-storied")
    document = json.loads((out / "metrics.json").read_text())
    assert document["edp"]["stories"] == ["story-1", "story-2"]
    assert document["edp"]["heights_m"] == [3.0, 2.5]
    assert document["edp"]["floors"] == ["ground", "dof-1", "dof-2"]
    assert document["edp"]["true_pfa_from"] == "displacement"
    for label, row in document["models"].items():
        for key, width in (("PID", 2), ("PFA", 2)):
            errors = row["edp"][key]
            assert len(errors["median"]) == len(errors["p90"]) == width, label
            assert all(0 <= m <= p for m, p in zip(errors["median"], errors["p90"], strict=True))
    refined = document["models"]["refined-c-phystoy-operator-toy-linear"]
    for level in (68, 90):
        coverage = refined[f"edp_coverage_{level}"]
        assert len(coverage["PID"]) == len(coverage["RID"]) == 2
        assert all(0.0 <= c <= 1.0 for c in coverage["PID"] + coverage["RID"])
    assert all(
        a <= b
        for a, b in zip(
            refined["edp_coverage_68"]["PID"], refined["edp_coverage_90"]["PID"], strict=True
        )
    )
    assert "edp_coverage_68" not in document["models"]["toy-operator"]

    # The numbers are those of edp.compute on the test records.
    data = cp.load_dataset(out / "dataset.h5")
    structure = cp.create("structure", "toy-storied")
    motions = data.motions("test")
    truth = edp.compute(data.targets("test"), structure, motions)
    physics = edp.compute(data.physics("toy-linear", "test"), structure, motions)
    expected = edp.log_errors(physics, truth)
    np.testing.assert_allclose(
        document["models"]["physics-toy-linear"]["edp"]["PID"]["median"],
        expected["PID"]["median"],
    )
    np.testing.assert_allclose(evaluation.true_edps.pfa, truth.pfa)

    # The baselines: fitted on the training records' simulated EDPs, scored on the test ones.
    train_rows = data.rows("train")
    train = edp.compute(
        data.u[train_rows], structure, cp.GroundMotions(data.ag[train_rows], data.dt)
    )
    t1 = float(structure.periods(1)[0])
    cloud = baselines.CloudRegression().fit(
        baselines.sa_t1(cp.GroundMotions(data.ag[train_rows], data.dt), t1),
        np.column_stack([train.pid, train.pfa[:, 1:]]),
    )
    predicted = cloud.predict(baselines.sa_t1(motions, t1))
    ratio = np.abs(np.log(predicted[:, :2] / truth.pid))
    np.testing.assert_allclose(
        document["baselines"]["baseline-cloud"]["edp"]["PID"]["median"], np.median(ratio, axis=0)
    )
    assert set(document["baselines"]) == {"baseline-cloud", "baseline-gp"}
    for label in document["models"]:
        assert "validation_edp" in document["models"][label], label
    assert isinstance(document["baseline_beats_surrogates"], list)

    report = (out / "report.md").read_text()
    assert (
        "## Physics inputs\n\n### `toy-linear`\n\nToy linear oscillators at (1.0, 3.0) Hz."
        in report
    )
    saved = out / "models" / "c-phystoy-operator-toy-linear" / "preprocessor" / "summary.md"
    assert saved.read_text() == "Toy linear oscillators at (1.0, 3.0) Hz.\n"
    loaded = cp.CompositeModel.load(saved.parents[1])  # the preprocessor restores from it
    assert loaded.preprocessor.restored_from_ == saved.parent
    assert "| baseline-gp |" in report and "Gaussian process on ln PGA" in report
    assert "## Engineering demand parameters (test split)" in report
    assert "| model | story-1 | story-2 |" in report
    assert "| model | dof-1 | dof-2 |" in report
    assert "### Drift bounds from the refined intervals" in report
    row = document["models"]["c-phystoy-operator-toy-linear"]["edp"]["PID"]
    assert f"{row['median'][0]:.3f} ({row['p90'][0]:.3f})" in report
    assert (out / "figures" / "edp_scatter.png").stat().st_size > 1000
    assert "figures/edp_scatter.png" in report


def test_a_structure_without_stories_gets_a_note_and_no_edps(toy_registry, tmp_path):
    out, evaluation = _run(tmp_path, "toy-structure", figures="false")
    document = json.loads((out / "metrics.json").read_text())
    assert document["edp"] is None
    assert all("edp" not in row for row in document["models"].values())
    assert document["baselines"] == {} and document["baseline_beats_surrogates"] == []
    assert evaluation.true_edps is None and not evaluation.predicted_edps
    report = (out / "report.md").read_text()
    assert "The structure `toy-structure` declares no stories" in report
