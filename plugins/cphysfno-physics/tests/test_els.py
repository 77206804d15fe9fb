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
    """Example 1 as specified: the ELS alone is at relative L2 of about 0.45-0.50 per story."""
    z = create("preprocessor", "els").fit(building).transform(paper_motions)
    error = relative_l2(z, paper_truth)
    print(f"ELS relative L2 to truth per story: {np.round(error, 3)}")
    assert np.all((error > 0.35) & (error < 0.6))


def _isolator(alpha: float = 0.1):
    """One story on a bilinear spring (an isolator's law): 2e5 kg, 4e6 N/m, yield at 2 cm."""
    return create(
        "structure",
        "shear-building",
        masses=(2.0e5,),
        stiffnesses=(4.0e6,),
        story_heights=(1.0,),
        story_law={"name": "bilinear", "alpha": alpha, "yield_displacement": 0.02},
    )


def _records(peak: float, n: int = 4) -> GroundMotions:
    rng = np.random.default_rng(3)
    ag = rng.standard_normal((n, 1501))
    return GroundMotions(peak * ag / np.abs(ag).max(axis=1, keepdims=True), 0.01)


def test_secant_els_solves_each_record_at_the_secant_of_its_own_peak():
    structure = _isolator()
    els = create(
        "preprocessor", "els", stiffness="secant", target_drift_ratio=0.1, hysteretic_damping=False
    ).fit(structure)
    motions = _records(3.0)
    z = els.transform(motions)
    system = structure.linear_system()
    k0 = system.stiffness[0, 0]
    for i in range(motions.n_records):
        peak = np.abs(z[i, :, 0]).max()
        assert peak > 0.02  # past yield
        # the bilinear backbone's secant at the peak: F(D) / D over k0
        secant = (0.02 + 0.1 * (peak - 0.02)) / peak
        soft = dataclasses.replace(system, stiffness=secant * system.stiffness)
        again = create("preprocessor", "els").fit(structure)
        again.system_ = soft
        alone = again.transform(motions[i])[0]
        # the bracket's last halving leaves s within 1e-4 of the initial stiffness
        np.testing.assert_allclose(z[i], alone, rtol=0, atol=0.01 * peak)
    assert k0 == 4.0e6


def test_secant_els_of_a_softening_story_keeps_the_secants_that_are_left():
    """alpha = -0.5: the story's strength is gone past 3 yield drifts (6 cm); the pushover
    to 10 % goes beyond, where no secant stiffness is left, and the secant curve stops."""
    els = create("preprocessor", "els", stiffness="secant", target_drift_ratio=0.1).fit(
        _isolator(alpha=-0.5)
    )
    roof, secant = els.secant_
    assert roof.max() < 0.06 and secant.min() > 0.0
    z = els.transform(_records(3.0))
    assert np.isfinite(z).all()


def test_secant_els_is_the_initial_one_below_yield_and_closer_past_it(relative_l2):
    structure = _isolator()
    initial = create("preprocessor", "els").fit(structure)
    secant = create("preprocessor", "els", stiffness="secant").fit(structure)
    weak = _records(0.05)
    np.testing.assert_allclose(secant.transform(weak), initial.transform(weak), rtol=1e-12)
    strong = _records(3.0, n=12)
    truth = structure.simulate(strong).displacement
    assert relative_l2(secant.transform(strong), truth) < relative_l2(
        initial.transform(strong), truth
    )


def test_secant_els_needs_a_pushover(toy):
    import pytest

    from cphysfno_core import CapabilityError

    with pytest.raises(CapabilityError, match="pushover"):
        create("preprocessor", "els", stiffness="secant").fit(toy)
