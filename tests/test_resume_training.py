"""Training killed after any epoch and resumed from its checkpoint ends with the same
weights as an uninterrupted run (CPU, same seed)."""

import pytest
import torch
from toy_experiment import toy_experiment
from toy_training import fit_toy, toy_data

import cphysfno_core as cp
from cphysfno_core.app import pipeline
from cphysfno_core.app.cli import main


class Killed(Exception):
    pass


@pytest.mark.parametrize("killed_after", [1, 3, 5])
def test_resumed_training_matches_an_uninterrupted_run(toy_registry, tmp_path, killed_after):
    structure, gm, u = toy_data()
    reference = fit_toy(structure, gm, u, progress=None)

    def kill(report):
        if report.epoch == killed_after:
            raise Killed

    checkpoint = tmp_path / "ckpt.pt"
    with pytest.raises(Killed):
        fit_toy(structure, gm, u, progress=kill, checkpoint=checkpoint)
    resumed = fit_toy(structure, gm, u, progress=None, checkpoint=checkpoint, resume=True)
    for key, value in reference.operator_.state_dict().items():
        assert torch.equal(resumed.operator_.state_dict()[key], value), key
    assert resumed.history_.val_loss == reference.history_.val_loss
    assert resumed.history_.best_epoch == reference.history_.best_epoch


def test_a_corrupt_checkpoint_is_a_clear_error(toy_registry, tmp_path):
    structure, gm, u = toy_data()
    checkpoint = tmp_path / "ckpt.pt"
    checkpoint.write_bytes(b"not a checkpoint")
    with pytest.raises(cp.DatasetError, match="cannot resume from .*remove it"):
        fit_toy(structure, gm, u, progress=None, checkpoint=checkpoint, resume=True)


CONFIG = toy_experiment(
    structure={"cubic": 30.0},
    n_steps=80,
    data={"n_train": 8, "n_val": 3, "n_test": 3},
    training={"epochs": 4, "batch_size": 4},
)


def test_train_resume_keeps_finished_models_and_continues_the_interrupted_one(
    toy_registry, tmp_path, monkeypatch, capsys
):
    path = tmp_path / "c.toml"
    path.write_text(CONFIG)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    reference = cp.CompositeModel.load(out / "models" / "c-phystoy-operator-toy-linear")
    original_fit = cp.CompositeModel.fit

    def interrupted_fit(self, *args, **kwargs):
        if self.preprocessor is not None:
            kwargs["progress"] = lambda r: (
                (_ for _ in ()).throw(KeyboardInterrupt) if r.epoch == 2 else None
            )
        return original_fit(self, *args, **kwargs)

    monkeypatch.setattr(cp.CompositeModel, "fit", interrupted_fit)
    assert main(["train", str(path), "--out", str(out)]) == 130
    assert (out / "models" / "c-phystoy-operator-toy-linear.checkpoint.pt").exists()
    monkeypatch.setattr(cp.CompositeModel, "fit", original_fit)
    capsys.readouterr()
    assert main(["train", str(path), "--out", str(out), "--resume"]) == 0
    assert "toy-operator is trained already" in capsys.readouterr().err
    resumed = cp.CompositeModel.load(out / "models" / "c-phystoy-operator-toy-linear")
    for key, value in reference.operator_.state_dict().items():
        assert torch.equal(resumed.operator_.state_dict()[key], value), key
    assert not (out / "models" / "c-phystoy-operator-toy-linear.checkpoint.pt").exists()
    pipeline.evaluate(cp.load_config(path), out)
