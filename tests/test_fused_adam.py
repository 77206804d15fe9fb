"""On the CPU the trainer's Adam (AdamW) runs fused, and trains as the standard one does."""

import numpy as np
import torch
from toy_training import fit_toy, toy_data

from cphysfno_core.model import training


def test_the_fused_adam_trains_as_the_standard_one(toy_registry, monkeypatch):
    made = []
    adam = torch.optim.AdamW

    def recording_adam(*args, **kwargs):
        made.append(kwargs)
        return adam(*args, **kwargs)

    monkeypatch.setattr(torch.optim, "AdamW", recording_adam)
    data = toy_data()
    fused = fit_toy(*data, progress=None)
    monkeypatch.setattr(training, "FUSED_ADAM_DEVICES", ())
    standard = fit_toy(*data, progress=None)

    assert [kwargs["fused"] for kwargs in made] == [True, False]
    for key, value in standard.operator_.state_dict().items():
        torch.testing.assert_close(fused.operator_.state_dict()[key], value, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(fused.history_.val_loss, standard.history_.val_loss, rtol=1e-4)
