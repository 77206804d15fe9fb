"""The structure passes the conformance checks every structure must pass."""

import numpy as np
import pytest
from cphysfno_core import Responses
from cphysfno_core.plugin import LinearSystem
from cphysfno_core.testing import check_structure

from cphysfno_bouc_wen import BoucWenShearBuilding


def test_default_building_conforms():
    check_structure(BoucWenShearBuilding())


def test_a_three_story_float64_building_conforms():
    check_structure(
        BoucWenShearBuilding(
            masses=(2e4, 2e4, 1e4), stiffnesses=(5e7, 4e7, 2e7), precision="float64"
        )
    )


class StiffLinearSystem(BoucWenShearBuilding):
    """Its linear system is 30 % stiffer than the building it simulates."""

    def linear_system(self):
        system = super().linear_system()
        return LinearSystem(
            system.mass,
            system.damping,
            1.3 * system.stiffness,
            system.influence,
            system.output_map,
        )


class AnswersInMillimetres(BoucWenShearBuilding):
    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions, dt=dt)
        return Responses(1000.0 * responses.displacement, responses.dt)


class SignFlipped(BoucWenShearBuilding):
    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions, dt=dt)
        return Responses(-responses.displacement, responses.dt)


class ProjectionIgnoresBasis(BoucWenShearBuilding):
    def simulate_projected(self, motions, basis, *, substeps=None):
        return self.simulate(motions)


class PeriodsTwiceTooLong(BoucWenShearBuilding):
    def periods(self, n=None):
        return 2.0 * super().periods(n)


class OutputsReversed(BoucWenShearBuilding):
    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions, dt=dt)
        return Responses(responses.displacement[..., ::-1].copy(), responses.dt)


@pytest.mark.parametrize(
    ("wrong", "message"),
    [
        (StiffLinearSystem, "periods\\(\\) .* are not the eigenperiods"),
        (AnswersInMillimetres, "amplitude is 1e\\+03 times the linear one: units"),
        (SignFlipped, "runs against the linear one: sign"),
        (ProjectionIgnoresBasis, "simulate_projected\\(\\) on the first mode .* basis"),
        (PeriodsTwiceTooLong, "periods\\(\\) .* are not the eigenperiods"),
        (OutputsReversed, "output order"),
    ],
)
def test_a_structure_whose_capabilities_lie_about_its_physics_fails(wrong, message):
    with pytest.raises(AssertionError, match=message):
        check_structure(wrong())


def test_a_linear_system_too_stiff_fails_the_response_check_too():
    """With periods() taken from the (wrong) linear system, the small-amplitude response
    still gives it away."""

    class Consistent(StiffLinearSystem):
        def periods(self, n=None):
            system = self.linear_system()
            squares = np.linalg.eigvals(np.linalg.solve(system.mass, system.stiffness))
            return (2 * np.pi / np.sqrt(np.sort(squares.real)))[:n]

    with pytest.raises(AssertionError, match="at small amplitude simulate\\(\\) is"):
        check_structure(Consistent())
