"""The neuralop FNO adapter passes the conformance checks every operator must pass."""

from cphysfno_core.testing import check_operator

from cphysfno_neuralop import NeuralopFNO

SMALL = dict(layers=2, modes=6, width=8, projection_width=8)


def test_paper_like_adapter_conforms():
    check_operator(NeuralopFNO, **SMALL)


def test_adapter_with_neuralop_options_conforms():
    check_operator(
        NeuralopFNO,
        **SMALL,
        lifting_width=12,
        domain_padding=0.1,
        use_channel_mlp=True,
        positional_embedding="grid",
    )
