"""Examples 2 and 3: the shipped configs validate with the paper's sizes, and a tiny
variant of each demo config runs generate -> train -> evaluate on the OpenSees models."""

from __future__ import annotations

import json
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.app import pipeline
from cphysfno_core.data.generation import grouped_order

EXAMPLES = Path(__file__).parents[3] / "examples"
PIERS = [f"pier-{i}" for i in range(1, 11)]
LEVELS = [f"level-{i}" for i in range(2, 10)] + ["roof"]
LABELS = {
    "fno",
    "c-physfno-els",
    "c-physfno-relaxed",
    "refined-c-physfno-els",
    "refined-c-physfno-relaxed",
    "physics-els",
    "physics-relaxed",
}


def _read(name: str) -> dict:
    return tomllib.loads((EXAMPLES / f"{name}.toml").read_text())


@pytest.mark.parametrize("name", ["bridge", "bridge-demo", "sac9-frame", "sac9-frame-demo"])
def test_the_config_validates(name):
    config = cp.load_config(EXAMPLES / f"{name}.toml")
    assert [p.name for p in config.preprocessor] == ["els", "relaxed"]
    assert config.refiner.name == "linear-regression" and config.output.baseline


@pytest.mark.parametrize(
    ("name", "structure", "reference"),
    [("bridge", "auburn-ravine-bridge", "example2"), ("sac9-frame", "sac9-frame", "example3")],
)
def test_the_full_configs_have_the_papers_sizes(name, structure, reference):
    config = cp.load_config(EXAMPLES / f"{name}.toml")
    assert config.structure.name == structure
    assert (config.data.n_train, config.data.n_val, config.data.n_test) == (600, 100, 300)
    fno = config.operator[0]
    assert fno.name == "fno" and (fno.params["layers"], fno.params["modes"]) == (8, 40)
    assert fno.params["width"] == 128
    training = config.training
    assert (training.epochs, training.batch_size, training.learning_rate) == (100, 20, 1e-3)
    assert (training.decay_step, training.decay_factor) == (10, 0.5)
    assert config.output.paper_reference == reference


def test_the_bridge_records_are_the_papers_scenario():
    motion = cp.load_config(EXAMPLES / "bridge.toml").ground_motion
    assert motion.name == "spectrum-compatible"
    assert motion.params["rjb_km"] == 5.0
    assert (motion.params["dt"], motion.params["duration"]) == (0.01, 30.0)


def test_the_frame_records_make_1000_split_by_recording():
    config = cp.load_config(EXAMPLES / "sac9-frame.toml")
    assert config.data.group_by == "rsn"
    source = cp.create("ground_motion", config.ground_motion.name, **config.ground_motion.params)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motions = source.sample(1000, np.random.default_rng(config.data.seed))
    assert not [w for w in caught if "asked for" in str(w.message)]  # all 1000 are there
    assert motions.acceleration.shape == (1000, 4001) and motions.dt == 0.005
    recordings = [str(m["rsn"]) for m in motions.metadata]
    assert set(np.unique(recordings, return_counts=True)[1]) == {20}  # 2 components x 10
    sizes = (config.data.n_train, config.data.n_val, config.data.n_test)
    order = grouped_order(recordings, sizes, np.random.default_rng(0))
    test_recordings = {recordings[i] for i in order[700:]}
    assert len(test_recordings) == 15 and not test_recordings & {recordings[i] for i in order[:700]}


@pytest.mark.parametrize(
    ("name", "outputs", "motions"),
    [
        ("bridge-demo", PIERS, {"period_band": [0.1, 1.0]}),  # 3 s hold two 1 s cycles
        ("sac9-frame-demo", LEVELS, {}),
    ],
)
def test_a_tiny_demo_runs_end_to_end(name, outputs, motions, tmp_path):
    data = _read(name)
    data["ground_motion"].update(duration=3.0, **motions)
    data["data"].update(n_train=4, n_val=2, n_test=2, chunk_size=8)
    data["operator"][0].update(layers=1, modes=4, width=4, projection_width=8)
    data["training"].update(epochs=1, batch_size=4)
    data["output"]["figures"] = False
    config = cp.parse_config(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # records short of the matching band, etc.
        pipeline.generate(config, tmp_path)
    pipeline.train(config, tmp_path)
    pipeline.evaluate(config, tmp_path)
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert set(metrics["models"]) == LABELS
    assert metrics["output_names"] == outputs
    assert metrics["sizes"] == {"train": 4, "val": 2, "test": 2}
    for label, row in metrics["models"].items():
        assert len(row["rel_l2"]) == len(outputs) and len(row["rmse"]) == len(outputs), label
        assert np.all(np.isfinite(row["rel_l2"])), label
    dataset = cp.load_dataset(tmp_path / "dataset.h5")
    assert dataset.u.shape == (8, 301 if name == "bridge-demo" else 601, len(outputs))
    assert np.abs(dataset.u).max() > 1e-4 and not dataset.failures
