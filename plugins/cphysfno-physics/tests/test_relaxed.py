"""Relaxed solver: the structure's coarse simulation interpolated back onto the fine grid,
the motion low-passed before it is decimated onto the coarse grid."""

from __future__ import annotations

import numpy as np
from cphysfno_physics.relaxed import coarse_motions

from cphysfno_core import GroundMotions, create


def test_factor_one_is_the_structure_simulation(toy, toy_motions, toy_truth):
    z = create("preprocessor", "relaxed", factor=1).fit(toy).transform(toy_motions)
    assert z.dtype == np.float64
    np.testing.assert_allclose(z, toy_truth, rtol=0, atol=1e-12)


def test_coarse_response_is_interpolated_like_numpy_interp(toy, toy_motions):
    relaxed = create("preprocessor", "relaxed", factor=7, anti_alias=False)
    z = relaxed.fit(toy).transform(toy_motions)
    coarse = toy.simulate(toy_motions, dt=7 * toy_motions.dt)
    assert z.shape == (toy_motions.n_records, toy_motions.n_steps, toy.n_outputs)
    for record in range(toy_motions.n_records):
        for output in range(toy.n_outputs):
            expected = np.interp(
                toy_motions.time, coarse.time, coarse.displacement[record, :, output]
            )
            np.testing.assert_allclose(z[record, :, output], expected, rtol=0, atol=1e-15)


def test_factor_one_reproduces_the_building(building, paper_motions, paper_truth, relative_l2):
    motions = paper_motions[:4]
    z = create("preprocessor", "relaxed", factor=1).fit(building).transform(motions)
    error = relative_l2(z, paper_truth[:4])
    print(f"relaxed k=1 relative L2 to the full model per story: {error}")
    assert np.all(error <= 1e-3)


def test_coarse_motions_keep_what_the_coarse_grid_carries_and_remove_the_rest():
    t = np.arange(301) * 0.01
    slow, fast = np.sin(2 * np.pi * 2.0 * t), np.sin(2 * np.pi * 18.0 * t)
    coarse = coarse_motions(GroundMotions(np.stack([slow, fast]), 0.01), 4)
    assert coarse.n_steps == 76 and coarse.dt == 0.04  # covers 0 ... 3 s
    inside = slice(5, -5)  # away from the cut ends of the sinusoids
    # 2 Hz lies well below the coarse Nyquist frequency 12.5 Hz: sampled as it is.
    np.testing.assert_allclose(coarse.acceleration[0, inside], slow[::4][inside], atol=2e-3)
    assert np.abs(coarse.acceleration[1, inside]).max() < 1e-2  # 18 Hz: gone, not folded
    uneven = coarse_motions(GroundMotions(np.stack([slow[:299], fast[:299]]), 0.01), 4)
    assert uneven.n_steps == 76  # 2.98 s, padded to whole coarse steps
    same = GroundMotions(np.stack([slow, fast]), 0.01)
    assert coarse_motions(same, 1) is same


def test_content_that_would_fold_onto_a_mode_is_filtered_out(toy, relative_l2):
    # A 1.3 Hz motion plus a sinusoid that the 0.04 s grid (k = 4) would see at the
    # building's first frequency: sampled point by point, it drives a resonance that the
    # fine grid does not have.
    t = np.arange(301) * 0.01
    aliased = 1.0 / 0.04 - 1.0 / toy.periods(1)[0]
    ag = (0.5 * np.sin(2 * np.pi * 1.3 * t) + np.sin(2 * np.pi * aliased * t)) * np.sin(
        np.pi * t / t[-1]
    ) ** 2
    motions = GroundMotions(ag, 0.01)
    truth = toy.simulate(motions).displacement
    filtered = create("preprocessor", "relaxed", factor=4).fit(toy).transform(motions)
    folded = create("preprocessor", "relaxed", factor=4, anti_alias=False)
    folded = folded.fit(toy).transform(motions)
    print(
        f"k=4 rel. L2 filtered {relative_l2(filtered, truth)}, folded {relative_l2(folded, truth)}"
    )
    assert np.all(relative_l2(filtered, truth) < 0.1)
    assert np.all(relative_l2(folded, truth) > 3.0)


def test_paper_factor_on_the_building(building, paper_motions, paper_truth, relative_l2):
    """White noise up to 20 Hz, k = 30: the coarse grid's Nyquist frequency (1.67 Hz) lies
    below the building's first mode (2.05 Hz), so no coarse solver can carry its response.
    The bound is computed here: the building's own fine-grid response to the motion with
    every component above 1.67 Hz removed (an ideal FFT filter) is already 0.9 or more away
    from the truth on every story. The relaxed response is there too, between that and zero
    (1.0); sampled as it is, the noise folds onto the modes and lands further than zero."""
    z = create("preprocessor", "relaxed").fit(building).transform(paper_motions)
    assert z.shape == paper_truth.shape and np.all(np.isfinite(z))
    ag = paper_motions.acceleration
    spectrum = np.fft.rfft(ag, axis=1)
    spectrum[:, np.fft.rfftfreq(ag.shape[1], paper_motions.dt) > 1.0 / (2 * 30 * 0.01)] = 0.0
    low = GroundMotions(np.fft.irfft(spectrum, n=ag.shape[1], axis=1), paper_motions.dt)
    ideal_error = relative_l2(building.simulate(low).displacement, paper_truth)
    error = relative_l2(z, paper_truth)
    folded = create("preprocessor", "relaxed", anti_alias=False).fit(building)
    folded_error = relative_l2(folded.transform(paper_motions), paper_truth)
    print(f"relaxed k=30 per story: {np.round(error, 3)}, ideal low-pass alone "
          f"{np.round(ideal_error, 3)}, without filter: {np.round(folded_error, 3)}")  # fmt: skip
    assert np.all(ideal_error > 0.85)
    assert np.all((error >= ideal_error - 0.05) & (error < 1.0))
    assert np.all(folded_error > 1.1)


def test_a_finer_grid_on_the_building_follows_the_truth(
    building, paper_motions, paper_truth, relative_l2
):
    z = create("preprocessor", "relaxed", factor=10).fit(building).transform(paper_motions)
    folded = create("preprocessor", "relaxed", factor=10, anti_alias=False).fit(building)
    error = relative_l2(z, paper_truth)
    folded_error = relative_l2(folded.transform(paper_motions), paper_truth)
    print(f"relaxed k=10 per story: {np.round(error, 3)}, without: {np.round(folded_error, 3)}")
    assert np.all(error < 0.4) and np.all(folded_error > 0.9)
