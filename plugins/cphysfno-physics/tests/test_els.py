"""ELS: the structure's linear system solved exactly, and how far it is from the truth."""

from __future__ import annotations

import dataclasses

import numpy as np

from cphysfno_core import GroundMotions, create


def test_els_is_the_linear_response_of_the_linear_system(toy, toy_motions, lsim_response):
    z = create("preprocessor", "els").fit(toy).transform(toy_motions)
    reference = lsim_response(toy.linear_system(), toy_motions)
    assert z.shape == (toy_motions.n_records, toy_motions.n_steps, toy.n_outputs)
    assert z.dtype == np.float64
    assert np.max(np.abs(z - reference)) <= 1e-8 * np.max(np.abs(reference))


def test_stiffness_scale_multiplies_the_elastic_stiffness(toy, toy_motions, lsim_response):
    z = create("preprocessor", "els", stiffness_scale=0.6).fit(toy).transform(toy_motions)
    system = toy.linear_system()
    softened = dataclasses.replace(system, stiffness=0.6 * system.stiffness)
    reference = lsim_response(softened, toy_motions)
    assert np.max(np.abs(z - reference)) <= 1e-8 * np.max(np.abs(reference))


def test_els_equals_the_nonlinear_model_at_tiny_amplitude(toy, toy_motions, relative_l2):
    tiny = GroundMotions(1e-3 * toy_motions.acceleration, toy_motions.dt)
    z = create("preprocessor", "els").fit(toy).transform(tiny)
    assert np.all(relative_l2(z, toy.simulate(tiny).displacement) <= 1e-3)


def test_toy_motions_drive_the_toy_far_from_linear(toy, toy_motions, toy_truth, relative_l2):
    z = create("preprocessor", "els").fit(toy).transform(toy_motions)
    assert np.all(relative_l2(z, toy_truth) > 0.2)


def test_els_on_the_building_is_its_linear_response(building, paper_motions, lsim_response):
    motions = paper_motions[:2]
    z = create("preprocessor", "els").fit(building).transform(motions)
    reference = lsim_response(building.linear_system(), motions)
    assert z.shape == (2, motions.n_steps, 5)
    assert np.max(np.abs(z - reference)) <= 1e-8 * np.max(np.abs(reference))


def test_els_on_the_building_at_tiny_amplitude(building, paper_motions, relative_l2):
    tiny = GroundMotions(1e-3 * paper_motions.acceleration[:3], paper_motions.dt)
    z = create("preprocessor", "els").fit(building).transform(tiny)
    assert np.all(relative_l2(z, building.simulate(tiny).displacement) <= 1e-3)


def test_els_error_on_paper_white_noise(building, paper_motions, paper_truth, relative_l2):
    """DESIGN.md: the ELS alone is at relative L2 of about 0.45-0.50 per story."""
    z = create("preprocessor", "els").fit(building).transform(paper_motions)
    error = relative_l2(z, paper_truth)
    print(f"ELS relative L2 to truth per story: {np.round(error, 3)}")
    assert np.all((error > 0.35) & (error < 0.6))
