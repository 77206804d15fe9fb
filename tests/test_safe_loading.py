"""Saved models load without executing code from the files; damaged files say so."""

import json
import pickle

import numpy as np
import pytest
import torch

import cphysfno_core as cp


class _Exploit:
    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (open, (str(self.marker), "w"))


@pytest.fixture
def saved(trained_toy, tmp_path):
    return trained_toy[0].save(tmp_path / "model")


@pytest.mark.filterwarnings("ignore:Detected pickle protocol")
def test_a_malicious_pickle_is_refused_and_never_run(saved, tmp_path):
    marker = tmp_path / "pwned"
    with open(saved / "operator.pt", "wb") as f:
        pickle.dump({"weight": _Exploit(marker)}, f)
    with pytest.raises(cp.DatasetError, match="cannot load the model's weights"):
        cp.CompositeModel.load(saved)
    assert not marker.exists()
    with open(saved / "operator.pt", "rb") as f:  # the exploit is real: plain pickle runs it
        pickle.load(f)
    assert marker.exists()


def test_pickled_arrays_are_refused(saved, tmp_path):
    arrays = dict(np.load(saved / "arrays.npz"))
    arrays["input_mean"] = np.array([_Exploit(tmp_path / "pwned")], dtype=object)
    np.savez(saved / "arrays.npz", **arrays)
    with pytest.raises(cp.DatasetError, match="Object arrays cannot be loaded"):
        cp.CompositeModel.load(saved)
    assert not (tmp_path / "pwned").exists()


def test_a_truncated_weight_file_is_a_clear_error(saved):
    data = (saved / "operator.pt").read_bytes()
    (saved / "operator.pt").write_bytes(data[: len(data) // 2])
    with pytest.raises(cp.DatasetError, match="cannot load the model's weights"):
        cp.CompositeModel.load(saved)


def test_weights_of_another_architecture_are_a_clear_error(saved):
    torch.save({"net.0.weight": torch.zeros(3, 3)}, saved / "operator.pt")
    with pytest.raises(cp.DatasetError, match="cannot load the model's weights"):
        cp.CompositeModel.load(saved)


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda d: d.update(format="something-else"), "is not a cphysfno-composite model"),
        (lambda d: d.pop("operator"), "operator: Field required"),
        (lambda d: d["operator"].pop("name"), "a part needs its registry name"),
        (lambda d: d.update(__class__="os.system"), "__class__: unknown field"),
    ],
)
def test_a_tampered_model_json_is_a_clear_error(saved, edit, message):
    description = json.loads((saved / "model.json").read_text())
    edit(description)
    (saved / "model.json").write_text(json.dumps(description))
    with pytest.raises(cp.DatasetError, match=message):
        cp.CompositeModel.load(saved)


def test_a_foreign_file_is_a_clear_error(saved):
    (saved / "model.json").write_text("\x89PNG\r\n")
    with pytest.raises(cp.DatasetError, match="is not a cphysfno-composite model"):
        cp.CompositeModel.load(saved)
