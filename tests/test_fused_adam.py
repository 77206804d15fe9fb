"""On the CPU the trainer's Adam runs fused, and trains as the standard Adam does."""

import numpy as np
import torch

import cphysfno_core as cp
from cphysfno_core import training


def _fit(toy_registry):
    structure = cp.create("structure", "toy-structure", cubic=30.0)
    gm = cp.create("ground_motion", "toy-source", n_steps=80).sample(14, np.random.default_rng(4))
    u = structure.simulate(gm).displacement
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator="toy-operator",
        training={"batch_size": 3, "seed": 5, "decay_step": 2},
    )
    model.fit(gm[:10], u[:10], validation=(gm[10:], u[10:]), epochs=6, progress=None)
    return model


def test_the_fused_adam_trains_as_the_standard_one(toy_registry, monkeypatch):
    made = []
    adam = torch.optim.Adam

    def recording_adam(*args, **kwargs):
        made.append(kwargs)
        return adam(*args, **kwargs)

    monkeypatch.setattr(torch.optim, "Adam", recording_adam)
    fused = _fit(toy_registry)
    monkeypatch.setattr(training, "FUSED_ADAM_DEVICES", ())
    standard = _fit(toy_registry)

    assert [kwargs["fused"] for kwargs in made] == [True, False]
    for key, value in standard.operator_.state_dict().items():
        torch.testing.assert_close(fused.operator_.state_dict()[key], value, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(fused.history_.val_loss, standard.history_.val_loss, rtol=1e-4)
