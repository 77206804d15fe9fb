"""The DeepONet passes the conformance checks every operator must pass."""

from cphysfno_core.testing import check_operator

from cphysfno_deeponet import DeepONet

SMALL = dict(sensors=16, latent=8, branch_width=16, trunk_width=16)


def test_deeponet_conforms():
    check_operator(DeepONet, **SMALL)


def test_deeponet_with_fourier_features_and_no_hidden_layers_conforms():
    check_operator(DeepONet, **SMALL, fourier_features=6, branch_layers=0, trunk_layers=0)
