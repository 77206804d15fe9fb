"""The components pass the conformance checks cphysfno asks of every structure and source."""

from cphysfno_core.testing import check_ground_motion_source, check_structure

from cphysfno_plugin_template import DuffingChain, KanaiTajimi


def test_duffing_chain_conforms():
    check_structure(DuffingChain())


def test_linear_single_story_conforms():
    check_structure(DuffingChain(masses=(1.0e4,), stiffnesses=(1.0e7,), cubic=0.0))


def test_kanai_tajimi_conforms():
    check_ground_motion_source(KanaiTajimi(duration=2.0))
