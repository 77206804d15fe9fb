"""The bridge passes the conformance checks every structure must pass."""

from cphysfno_opensees.bridge.structure import AuburnRavineBridge

from cphysfno_core.testing import check_structure


def test_a_coarsely_meshed_bridge_conforms():
    # A coarse fibre mesh, three integration points and one step per sample keep the
    # check quick; the checks do not depend on them.
    bridge = AuburnRavineBridge(
        sectors=8, core_rings=2, cover_rings=1, integration_points=3, substeps=1, workers=2
    )
    check_structure(bridge)
