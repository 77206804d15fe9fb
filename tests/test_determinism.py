"""Same config and seed: byte-identical dataset arrays and identical trained weights on CPU."""

import numpy as np
import torch

import cphysfno_core as cp

DATA = {
    "structure": {"name": "bouc-wen-shear-building"},
    "ground_motion": {"name": "white-noise", "duration": 4.0},
    "preprocessor": [{"name": "els"}],
    "operator": {"name": "fno", "layers": 2, "modes": 8, "width": 8, "projection_width": 8},
    "data": {"n_train": 6, "n_val": 2, "n_test": 2, "chunk_size": 4, "executor": "serial"},
}


def test_the_same_config_gives_byte_identical_datasets(tmp_path):
    config = cp.parse_config(DATA)
    first = cp.load_dataset(cp.generate_dataset(config, tmp_path / "a.h5", progress=False))
    second = cp.load_dataset(cp.generate_dataset(config, tmp_path / "b.h5", progress=False))
    for name in ("ag", "u"):
        assert getattr(first, name).tobytes() == getattr(second, name).tobytes()
    assert first.z["els"].tobytes() == second.z["els"].tobytes()


def test_the_same_seed_gives_identical_trained_weights():
    structure = cp.create("structure", "bouc-wen-shear-building")
    gm = cp.create("ground_motion", "white-noise", duration=4.0).sample(8, np.random.default_rng(1))
    u = structure.simulate(gm).displacement

    def trained() -> dict[str, torch.Tensor]:
        hyper = {k: v for k, v in DATA["operator"].items() if k != "name"}
        model = cp.compose(
            structure=structure,
            preprocessor="els",
            operator=("fno", hyper),
            training={"batch_size": 3, "seed": 11},
        )
        model.fit(gm[:6], u[:6], validation=(gm[6:], u[6:]), epochs=3, progress=None)
        return model.operator_.state_dict()

    first, second = trained(), trained()
    assert first.keys() == second.keys()
    for key in first:
        assert torch.equal(first[key], second[key]), key
