"""``examples/ablation/run_ablation.py`` on toy parts: every row trained as its tables say,
scored against the test split, refined by every refiner, and ensembles scored on their
rows' mean."""

import importlib.util
import json
from pathlib import Path

import numpy as np
from toy_experiment import toy_experiment

from cphysfno_core import CompositeModel, load_config, load_dataset
from cphysfno_core.reporting import metrics

SCRIPT = Path(__file__).parents[1] / "examples" / "ablation" / "run_ablation.py"

BASE = toy_experiment(
    structure={"cubic": 40.0},
    n_steps=80,
    operator={"width": 4},
    data={"n_train": 8, "n_val": 4, "n_test": 5},
    training={"epochs": 2, "batch_size": 4},
)

ABLATION = """
base = "base.toml"
preprocessor = "toy-linear"
seed = 3

[[refiner]]
label = "plain"
name = "toy-refiner"

[[refiner]]
label = "calibrated"
name = "toy-calibrated-refiner"

[[row]]
name = "as the base"

[[row]]
name = "Residual, wider!"
formulation = { residual = true }
operator = { width = 6 }
training = { epochs = 1 }

[[ensemble]]
name = "both"
rows = ["as the base", "Residual, wider!"]
"""


def test_every_row_is_trained_as_its_tables_say_and_scored_on_the_test_split(
    toy_registry, tmp_path
):
    spec = importlib.util.spec_from_file_location("run_ablation", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    (tmp_path / "base.toml").write_text(BASE)
    (tmp_path / "ablation.toml").write_text(ABLATION)
    out, result = tmp_path / "rows", tmp_path / "result.json"
    dataset = tmp_path / "dataset.h5"
    arguments = [str(tmp_path / "ablation.toml"), "--dataset", str(dataset)]
    study = tmp_path / "chosen.toml"
    options = ["--out", str(out), "--json", str(result), "--chosen-study", str(study)]
    assert module.main([*arguments, *options, "--seeds", "3"]) == 0
    document = json.loads(result.read_text())
    assert list(document["rows"]) == ["as the base", "Residual, wider!"]
    plain, changed = document["rows"].values()
    assert plain["operator"]["width"] == 4 and plain["training"]["epochs"] == 2
    assert changed["operator"]["width"] == 6 and changed["training"]["epochs"] == 1
    assert changed["formulation"]["residual"] and changed["training"]["seed"] == 3
    assert (out / "residual-wider" / "model.json").exists()
    data = load_dataset(dataset)
    truth, z = data.targets("test"), data.physics("toy-linear", "test")
    np.testing.assert_allclose(document["physics"]["rel_l2"], metrics.relative_l2(z, truth))
    for row in (plain, changed):
        assert row["meets_target"] == (max(row["rel_l2"]) <= 0.25)
        assert set(row["refined"]) == {"plain", "calibrated"}
        for refined in row["refined"].values():
            assert len(refined["coverage_68"]) == len(refined["coverage_90"]) == 2
            assert all(0.0 <= se <= 0.5 for se in refined["coverage_90_se"])
    members = [CompositeModel.load(out / name) for name in ("as-the-base", "residual-wider")]
    mean = np.mean([m.predict_stages(data.motions("test")).operator_output for m in members], 0)
    ensemble = document["ensembles"]["both"]
    np.testing.assert_allclose(ensemble["rel_l2"], metrics.relative_l2(mean, truth), rtol=1e-6)
    assert ensemble["rows"] == ["as the base", "Residual, wider!"]
    validation = [
        metrics.relative_l2(
            m.predict_stages(data.motions("val")).operator_output, data.targets("val")
        )
        for m in members
    ]
    for row, expected in zip((plain, changed), validation, strict=True):
        np.testing.assert_allclose(row["validation"]["rel_l2"], expected, rtol=1e-6)
    chosen = ["as the base", "Residual, wider!"][int(np.argmin([v.mean() for v in validation]))]
    assert document["selection"]["selected_on"] == "validation"
    assert document["selection"]["row"] == chosen
    assert document["selection"]["test_rel_l2"] == document["rows"][chosen]["rel_l2"]
    config = load_config(study)
    row = document["rows"][chosen]
    assert config.operator[0].to_dict() == row["operator"]
    assert config.formulation.model_dump() == row["formulation"]
    assert config.training.epochs == row["training"]["epochs"]
    assert [p.name for p in config.preprocessor] == ["toy-linear"]
    assert config.study.seeds == [0, 1, 2] and not config.output.baseline
