"""Modal reduction: all modes reproduce the full model, fewer modes do not."""

from __future__ import annotations

import numpy as np
import pytest

from cphysfno_core import ConfigError, create
from cphysfno_core.plugin import LinearSystem, Structure


def test_all_modes_reproduce_the_full_model(toy, toy_motions, toy_truth, relative_l2):
    z = create("preprocessor", "modal", modes=3).fit(toy).transform(toy_motions)
    assert z.shape == toy_truth.shape and z.dtype == np.float64
    assert np.all(relative_l2(z, toy_truth) <= 1e-4)


def test_fewer_modes_differ(toy, toy_motions, toy_truth, relative_l2):
    one, two = (
        relative_l2(
            create("preprocessor", "modal", modes=r).fit(toy).transform(toy_motions), toy_truth
        )
        for r in (1, 2)
    )
    assert np.all(two > 1e-3) and np.all(one > two)


def test_more_substeps_converge(toy, toy_motions, toy_truth, relative_l2):
    coarse = create("preprocessor", "modal", modes=3, substeps=1).fit(toy)
    fine = create("preprocessor", "modal", modes=3, substeps=6).fit(toy)
    coarse_error = relative_l2(coarse.transform(toy_motions), toy_truth)
    fine_error = relative_l2(fine.transform(toy_motions), toy_truth)
    assert np.all(fine_error < coarse_error / 100)


def test_modes_are_the_elastic_modes(toy):
    modal = create("preprocessor", "modal", modes=3).fit(toy)
    np.testing.assert_allclose(2 * np.pi / modal.frequencies_, toy.periods(), rtol=1e-10)
    mass = toy.linear_system().mass
    np.testing.assert_allclose(modal.shapes_.T @ mass @ modal.shapes_, np.eye(3), atol=1e-12)


def test_more_modes_than_dofs_is_a_config_error(toy):
    with pytest.raises(ConfigError, match=r"modal\.modes.*3 degrees of freedom.*toy-building"):
        create("preprocessor", "modal", modes=4).fit(toy)


def test_all_modes_reproduce_the_building(building, paper_motions, paper_truth, relative_l2):
    motions = paper_motions[:4]
    z = create("preprocessor", "modal", modes=5).fit(building).transform(motions)
    error = relative_l2(z, paper_truth[:4])
    print(f"modal r=5 relative L2 to the full model per story: {error}")
    assert np.all(error <= 1e-3)


def test_two_modes_on_the_building(building, paper_motions, paper_truth, relative_l2):
    z = create("preprocessor", "modal").fit(building).transform(paper_motions)
    error = relative_l2(z, paper_truth)
    print(f"modal r=2 relative L2 to truth per story: {np.round(error, 3)}")
    assert np.all(np.isfinite(z)) and np.all(error > 1e-3)


def test_the_structures_projected_simulation_is_the_generic_path(
    building, paper_motions, relative_l2
):
    """The Bouc-Wen building integrates the reduced model itself (compiled, float32);
    without that capability the preprocessor integrates it from the restoring force."""
    generic_type = type(
        "WithoutProjectedSimulation",
        (type(building),),
        {
            "simulate_projected": Structure.simulate_projected,
            "capabilities": building.capabilities - {"projected_simulation"},
        },
    )
    generic = generic_type(**building.get_params())
    assert "projected_simulation" in building.capabilities
    assert "projected_simulation" not in generic.capabilities
    motions = paper_motions[:3]
    fast = create("preprocessor", "modal").fit(building).transform(motions)
    reference = create("preprocessor", "modal").fit(generic).transform(motions)
    assert fast.shape == reference.shape and fast.dtype == np.float64
    assert np.all(relative_l2(fast, reference) <= 1e-5)


def test_without_a_restoring_force_all_modes_are_the_linear_response(
    toy_without_restoring_force, toy_motions, lsim_response, relative_l2
):
    modal = create("preprocessor", "modal", modes=3).fit(toy_without_restoring_force)
    assert modal.restoring_force_ is None
    expected = lsim_response(toy_without_restoring_force.linear_system(), toy_motions)
    assert np.all(relative_l2(modal.transform(toy_motions), expected) <= 1e-6)


def test_without_a_restoring_force_one_mode_is_the_first_modal_oscillator(
    toy_without_restoring_force, toy_motions, lsim_response, relative_l2
):
    """r = 1: the outputs are L phi_1 q_1 with q_1 the damped oscillator of mode 1."""
    system = toy_without_restoring_force.linear_system()
    frequencies, shapes = np.linalg.eig(np.linalg.solve(system.mass, system.stiffness))
    first = shapes[:, [np.argmin(frequencies)]].real
    first /= np.sqrt(first.T @ system.mass @ first)
    oscillator = LinearSystem(
        mass=np.eye(1),
        damping=first.T @ system.damping @ first,
        stiffness=np.array([[np.min(frequencies.real)]]),
        influence=first.T @ system.mass @ system.influence,
        output_map=system.output_map @ first,
    )
    expected = lsim_response(oscillator, toy_motions)
    one = create("preprocessor", "modal", modes=1).fit(toy_without_restoring_force)
    z = one.transform(toy_motions)
    assert np.all(relative_l2(z, expected) <= 1e-6)
    full = lsim_response(system, toy_motions)
    assert np.all(relative_l2(z, full) > 1e-3)
