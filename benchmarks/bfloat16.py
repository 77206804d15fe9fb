"""What predicting and training in bfloat16 cost in accuracy, on a trained model.

Example 1 of the paper (five-story Bouc–Wen shear building under white noise): a C-PhysFNO
on the ELS response at the paper's Example 1 operator size, with the linear-regression
refiner, trained here for a few dozen epochs on a few hundred records, once in float32 and
once with ``[training] precision = "bfloat16"`` (same seed and data). The first row predicts
the test records with the float32-trained model in float32 and in bfloat16
(``CompositeModel.predict(..., precision=...)``), side by side; the second puts the two
trainings side by side. The notes give the relative L2 errors against the Bouc–Wen truth.
"""

from __future__ import annotations

import time

import numpy as np
import torch

import cphysfno_core as cp
from cphysfno_core.reporting.metrics import relative_l2

from .common import Row, best_time
from .prediction import EXAMPLE1_OPERATOR

FULL = {"n_train": 200, "n_val": 50, "n_test": 200, "epochs": 40}
QUICK = {"n_train": 20, "n_val": 10, "n_test": 10, "epochs": 2}
"""Records per split and training epochs of a full and a quick run."""


def trained_model(
    n_train: int, n_val: int, n_test: int, epochs: int, precision: str = "float32"
) -> tuple[cp.CompositeModel, cp.GroundMotions, np.ndarray, float]:
    """A C-PhysFNO-ELS with linear regression trained ``epochs`` epochs in ``precision`` on
    ``n_train`` Example 1 records (``n_val`` for validation), ``n_test`` test motions with
    their true displacements ``[n_test, T, 5]`` (m), and the training time (s)."""
    rng = np.random.default_rng(0)
    total = n_train + n_val + n_test
    motions = cp.create("ground_motion", "white-noise").sample(total, rng)
    structure = cp.create("structure", "bouc-wen-shear-building")
    u = structure.simulate(motions).displacement
    train, val = slice(0, n_train), slice(n_train, n_train + n_val)
    test = slice(n_train + n_val, total)
    torch.manual_seed(0)
    model = cp.compose(
        structure=structure,
        preprocessor="els",
        operator=("fno", EXAMPLE1_OPERATOR),
        refiner="linear-regression",
        training={"batch_size": 20, "precision": precision},
    )
    start = time.perf_counter()
    model.fit(
        motions[train],
        u[train],
        validation=(motions[val], u[val]),
        epochs=epochs,
        progress=None,
    )
    return model, motions[test], u[test], time.perf_counter() - start


def run(quick: bool = False) -> list[Row]:
    sizes = QUICK if quick else FULL
    model, motions, truth, training_s = trained_model(**sizes)
    single_s = best_time(lambda: model.predict(motions))
    low_s = best_time(lambda: model.predict(motions, precision="bfloat16"))
    single = model.predict(motions)[0]
    low = model.predict(motions, precision="bfloat16")[0]
    error_single = float(relative_l2(single, truth).mean())
    error_low = float(relative_l2(low, truth).mean())
    change = float(relative_l2(low, single).mean())
    low_model, _, _, low_training_s = trained_model(**sizes, precision="bfloat16")
    trained_low = low_model.predict(motions)[0]
    trained_low_bf16 = low_model.predict(motions, precision="bfloat16")[0]
    epochs = sizes["epochs"]
    return [
        Row(
            stage=(
                f"bfloat16 prediction of {sizes['n_test']} Example 1 test records by a trained "
                "C-PhysFNO-ELS (6 x 32 modes, width 64) with linear regression"
            ),
            ours_s=low_s,
            alternative="the same model in float32",
            alternative_s=single_s,
            target="accuracy cost small beside the model's own error",
            notes=[
                f"relative L2 error against the Bouc-Wen truth, mean over stories: float32 "
                f"{error_single:.4f}, bfloat16 {error_low:.4f}; bfloat16 against float32 "
                f"{change:.1e}",
                f"trained {sizes['epochs']} epochs on {sizes['n_train']} records "
                f"({sizes['n_val']} for validation) in {training_s:.0f} s; best of 3 predictions",
            ],
        ),
        Row(
            stage=(
                f"training in bfloat16: the same model, {epochs} epochs on "
                f"{sizes['n_train']} records, [training] precision = 'bfloat16'"
            ),
            ours_s=low_training_s,
            alternative="the same training in float32 (same seed and data)",
            alternative_s=training_s,
            target="report",
            notes=[
                f"per epoch {low_training_s / epochs:.2f} s against {training_s / epochs:.2f} s",
                "relative L2 error against the Bouc-Wen truth, mean over stories, of the "
                f"bfloat16-trained model: {float(relative_l2(trained_low, truth).mean()):.4f} "
                "predicting in float32, "
                f"{float(relative_l2(trained_low_bf16, truth).mean()):.4f} in bfloat16 (the "
                f"float32-trained model: {error_single:.4f})",
            ],
        ),
    ]
