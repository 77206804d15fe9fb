"""The FNO passes the conformance checks every operator must pass."""

from cphysfno_fno import FNO1d

from cphysfno_core.testing import check_operator


def test_fno_conforms():
    check_operator(FNO1d, layers=2, modes=6, width=8, projection_width=8)


def test_padded_fno_conforms():
    check_operator(FNO1d, layers=2, modes=6, width=8, projection_width=8, padding=9)
