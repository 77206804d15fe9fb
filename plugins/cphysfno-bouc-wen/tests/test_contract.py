"""The structure passes the conformance checks every structure must pass."""

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
