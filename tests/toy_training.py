"""A small C-Phys model of the toy components, trained through ``CompositeModel.fit``."""

from __future__ import annotations

import numpy as np

import cphysfno_core as cp


def toy_data():
    """``(structure, motions, u)``: 14 records of 80 steps of the cubic toy structure."""
    structure = cp.create("structure", "toy-structure", cubic=30.0)
    gm = cp.create("ground_motion", "toy-source", n_steps=80).sample(14, np.random.default_rng(4))
    return structure, gm, structure.simulate(gm).displacement


def fit_toy(structure, gm, u, **fit_options) -> cp.CompositeModel:
    """``toy-linear`` + ``toy-operator`` trained for 6 epochs on the first 10 records,
    validated on the other 4 (batch 3, seed 5, rate halved every 2 epochs); ``fit_options``
    go to ``fit`` (``progress``, ``checkpoint``, ``resume``)."""
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator="toy-operator",
        training={"batch_size": 3, "seed": 5, "decay_step": 2},
    )
    model.fit(gm[:10], u[:10], validation=(gm[10:], u[10:]), epochs=6, **fit_options)
    return model
