"""Relaxed solver: the structure's coarse simulation interpolated back onto the fine grid."""

from __future__ import annotations

import numpy as np

from cphysfno_core import create


def test_factor_one_is_the_structure_simulation(toy, toy_motions, toy_truth):
    z = create("preprocessor", "relaxed", factor=1).fit(toy).transform(toy_motions)
    assert z.dtype == np.float64
    np.testing.assert_allclose(z, toy_truth, rtol=0, atol=1e-12)


def test_coarse_response_is_interpolated_like_numpy_interp(toy, toy_motions):
    z = create("preprocessor", "relaxed", factor=7).fit(toy).transform(toy_motions)
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


def test_paper_factor_on_the_building(building, paper_motions, paper_truth, relative_l2):
    z = create("preprocessor", "relaxed").fit(building).transform(paper_motions)
    assert z.shape == paper_truth.shape and np.all(np.isfinite(z))
    error = relative_l2(z, paper_truth)
    print(f"relaxed k=30 relative L2 to truth per story: {np.round(error, 3)}")
