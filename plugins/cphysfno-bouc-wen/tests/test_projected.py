"""The model Galerkin-projected onto a basis, against an independent projected reference."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from cphysfno_core import GroundMotions, InputError

from cphysfno_bouc_wen import BoucWenShearBuilding


@pytest.fixture(scope="module")
def motions(white_noise) -> GroundMotions:
    return GroundMotions(white_noise(2, seed=23, duration=6.0), 0.01)


def test_two_modes_match_the_projected_equations(
    motions, matrices, projected_reference_rhs, piecewise_solver, rel_l2
) -> None:
    mass, stiffness, damping = matrices
    _, modes = scipy.linalg.eigh(stiffness, mass)
    basis = modes[:, :2]
    rhs = projected_reference_rhs(basis, damping)
    projected = BoucWenShearBuilding().simulate_projected(motions, 3.0 * basis[:, ::-1])
    for record, ag in enumerate(motions.acceleration):
        y = piecewise_solver(rhs, np.zeros(9), ag, 0.01, rtol=1e-9, atol=1e-12)
        reference = y[:, :2] @ basis.T
        assert np.abs(np.diff(reference, axis=1, prepend=0.0)).max() > 0.01
        error = rel_l2(projected.displacement[record], reference)
        assert np.all(error <= 1e-3), f"record {record}: relative L2 per story {error}"


def test_an_invertible_basis_is_the_full_model(motions, rel_l2) -> None:
    building = BoucWenShearBuilding()
    basis = np.random.default_rng(0).normal(size=(5, 5))
    projected = building.simulate_projected(motions, basis, substeps=2)
    full = building.simulate(motions)
    assert set(projected.extras) == {"story_drift", "story_shear"}
    for name, values in [("displacement", projected.displacement), *projected.extras.items()]:
        expected = full.displacement if name == "displacement" else full.extras[name]
        assert np.all(rel_l2(values, expected) <= 1e-5), name


@pytest.mark.parametrize(
    ("basis", "substeps"),
    [(np.ones((5, 2)), None), (np.eye(4), None), (np.eye(5)[:, :2], 0)],
)
def test_bad_bases_and_substeps_are_input_errors(motions, basis, substeps) -> None:
    with pytest.raises(InputError, match="basis|substeps"):
        BoucWenShearBuilding().simulate_projected(motions, basis, substeps=substeps)
