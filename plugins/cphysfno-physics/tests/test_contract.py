"""Each preprocessor passes the conformance checks on the Bouc-Wen building."""

import pytest
from cphysfno_physics import EquivalentLinear, ModalReduction, RelaxedSolver

from cphysfno_core import create
from cphysfno_core.testing import check_preprocessor


@pytest.mark.parametrize(
    "preprocessor",
    [EquivalentLinear(), ModalReduction(), ModalReduction(modes=5), RelaxedSolver(factor=3)],
    ids=["els", "modal-2", "modal-5", "relaxed-3"],
)
def test_preprocessor_conforms(preprocessor):
    check_preprocessor(preprocessor, create("structure", "bouc-wen-shear-building"))
