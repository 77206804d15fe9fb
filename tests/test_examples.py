"""The shipped configs parse, and a tiny Example 1 runs end to end through the CLI with
the built-in plugins."""

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.app.cli import main

EXAMPLES = Path(__file__).parents[1] / "examples"


def test_every_example_config_is_valid():
    configs = sorted(EXAMPLES.glob("*.toml"))
    assert {p.name for p in configs} >= {"bouc-wen.toml", "bouc-wen-demo.toml"}
    for path in configs:
        cp.load_config(path)


def test_every_example_config_reads_back_from_its_toml():
    configs = sorted(EXAMPLES.glob("*.toml")) + sorted(EXAMPLES.glob("paper-setup/*.toml"))
    for path in configs:
        config = cp.load_config(path)
        assert cp.parse_config(tomllib.loads(config.to_toml())) == config, path.name


def test_paper_config_has_the_papers_sizes():
    config = cp.load_config(EXAMPLES / "bouc-wen.toml")
    assert (config.data.n_train, config.data.n_val, config.data.n_test) == (400, 100, 200)
    assert [o.name for o in config.operator] == ["fno", "deeponet"]
    assert config.operator[0].params == {
        "layers": 6,
        "modes": 32,
        "width": 64,
        "projection_width": 128,
    }
    assert (config.training.learning_rate, config.training.decay_factor) == (1e-3, 0.5)
    assert [p.name for p in config.preprocessor] == ["els", "modal", "relaxed"]


def test_the_study_config_is_the_paper_experiment_with_its_seeds_and_sweeps():
    paper = cp.load_config(EXAMPLES / "bouc-wen.toml").to_dict()
    assert paper.pop("study") is None
    paper["operator"] = paper["operator"][0]  # the paper's study is of the FNO alone
    study = cp.load_config(EXAMPLES / "bouc-wen-study.toml").to_dict()
    sweeps = study.pop("study")
    assert study == paper
    assert sweeps["seeds"] == list(range(10))
    assert sweeps["sweeps"]["training_size"]["values"][-1] == 400
    assert sweeps["sweeps"]["fourier_layers"]["field"] == "operator.layers"


def test_tiny_example1_runs_end_to_end(tmp_path, capsys):
    data = tomllib.loads((EXAMPLES / "bouc-wen-demo.toml").read_text())
    data["ground_motion"]["duration"] = 6.0
    data["data"].update(n_train=10, n_val=4, n_test=6, chunk_size=10, executor="serial")
    fno, deeponet = data["operator"]
    fno.update(layers=2, modes=8, width=8, projection_width=16)
    deeponet.update(sensors=32, latent=8, branch_width=16, trunk_width=16, fourier_features=8)
    data["training"].update(epochs=2, batch_size=5)
    path = tmp_path / "tiny.toml"
    path.write_text(cp.parse_config(data).to_toml())
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "story-5" in printed and "physics-els" in printed
    models = json.loads((out / "metrics.json").read_text())["models"]
    assert set(models) == {
        "fno",
        "c-physfno-els",
        "c-physfno-modal",
        "c-physfno-relaxed",
        "refined-c-physfno-els",
        "refined-c-physfno-modal",
        "refined-c-physfno-relaxed",
        "physics-els",
        "physics-modal",
        "physics-relaxed",
        "deeponet",
        "c-physdeeponet-els",
        "c-physdeeponet-modal",
        "c-physdeeponet-relaxed",
        "refined-c-physdeeponet-els",
        "refined-c-physdeeponet-modal",
        "refined-c-physdeeponet-relaxed",
    }
    assert all(len(row["rel_l2"]) == 5 for row in models.values())
    assert (out / "figures" / "hysteresis.png").exists()

    model = cp.CompositeModel.load(out / "models" / "c-physfno-els")
    gm = cp.create("ground_motion", "white-noise", duration=6.0).sample(3, np.random.default_rng(5))
    mean, std = model.predict(gm)
    assert mean.shape == std.shape == (3, 601, 5)
    assert np.isfinite(mean).all() and (std > 0).all()


def test_the_beyond_preset_is_the_ablation_row_chosen_on_validation():
    ablation = tomllib.loads((EXAMPLES / "ablation" / "bouc-wen-ablation.toml").read_text())
    results = json.loads((EXAMPLES.parent / "results" / "example1-ablation.json").read_text())
    selection = results["selection"]
    assert selection["selected_on"] == "validation"
    rows = results["rows"]
    assert selection["row"] == min(rows, key=lambda r: rows[r]["validation"]["rel_l2_mean"])
    row = next(r for r in ablation["row"] if r["name"] == selection["configuration"])
    base = cp.load_config(EXAMPLES / "ablation" / ablation["base"])
    preset = cp.load_config(EXAMPLES / "bouc-wen-beyond.toml")
    assert preset.operator[0].params == {**base.operator[0].params, **row["operator"]}
    assert preset.formulation.model_dump() == {
        **base.formulation.model_dump(),
        **row["formulation"],
    }
    training = {**base.training.model_dump(), **row["training"], "seed": ablation["seed"]}
    assert preset.training.model_dump() == training
    assert preset.data.model_dump() == base.data.model_dump()
    assert [p.name for p in preset.preprocessor] == [ablation["preprocessor"]]
    assert preset.study.seeds == list(range(10))


def test_the_cpu_configs_of_examples_2_and_3_are_the_full_ones_cut_down():
    for full, cpu, copies in [("bridge", "bridge-cpu", None), ("sac9-frame", "sac9-frame-cpu", 4)]:
        paper = cp.load_config(EXAMPLES / f"{full}.toml").to_dict()
        reduced = cp.load_config(EXAMPLES / f"{cpu}.toml").to_dict()
        assert reduced["data"]["n_train"] < paper["data"]["n_train"]
        assert reduced["training"]["epochs"] < paper["training"]["epochs"]
        for section in ("data", "training"):
            for key in ("n_train", "n_val", "n_test", "epochs", "decay_step"):
                paper[section].pop(key, None)
                reduced[section].pop(key, None)
        if copies is not None:
            assert reduced["ground_motion"].pop("copies") == copies
            paper["ground_motion"].pop("copies")
        reduced.pop("study")  # the full size alone repeats its training over seeds
        paper.pop("study")
        assert reduced == paper


@pytest.mark.parametrize(
    ("plain", "residual"),
    [("sac9-frame-cpu", "sac9-frame-cpu-residual"), ("sac9-frame", "sac9-frame-residual")],
)
def test_the_residual_frame_configs_reuse_their_frame_data(plain: str, residual: str):
    from cphysfno_core.data.datasets import dataset_hash

    paper = cp.load_config(EXAMPLES / f"{plain}.toml")
    beyond = cp.load_config(EXAMPLES / f"{residual}.toml")
    assert dataset_hash(beyond) == dataset_hash(paper)
    assert beyond.formulation.residual and beyond.formulation.ground_motion_input
    assert beyond.operator == paper.operator


@pytest.mark.parametrize("name", ["bouc-wen", "bridge"])
def test_paper_setup_configs_train_as_the_published_code(name):
    """examples/paper-setup/: the paper's example with the published MATLAB code's FNO
    (ReLU after every Fourier layer, Glorot init) and training (raw SI inputs and outputs)."""
    setup = cp.load_config(EXAMPLES / "paper-setup" / f"{name}.toml")
    ours = cp.load_config(EXAMPLES / f"{name}.toml")
    (fno,) = setup.operator
    assert fno.params == {
        **ours.operator[0].params,
        "activation": "relu",
        "activate_last_layer": True,
        "init": "glorot",
    }
    assert setup.training.normalize is False
    assert setup.training.model_copy(update={"normalize": True}) == ours.training
    assert (setup.structure, setup.ground_motion) == (ours.structure, ours.ground_motion)
    assert setup.data == ours.data
