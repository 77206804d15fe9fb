"""Any input either works or raises the package's own error: never a raw traceback."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import cphysfno_core as cp

floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
arrays = hnp.arrays(
    dtype=st.sampled_from([np.float64, np.float32, np.int64, np.bool_, np.complex128]),
    shape=hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=6),
    elements=None,
)
values = st.one_of(
    arrays,
    st.lists(st.one_of(floats, st.text(max_size=3)), max_size=6),
    floats,
    st.text(max_size=5),
    st.none(),
)
dts = st.one_of(floats, st.integers(-5, 5), st.text(max_size=4), st.none())


@given(acceleration=values, dt=dts)
@settings(max_examples=300, deadline=None)
def test_ground_motions_accept_or_explain(acceleration, dt):
    try:
        gm = cp.GroundMotions(acceleration, dt)
    except cp.InputError as error:
        assert str(error)
        return
    assert gm.acceleration.ndim == 2 and np.isfinite(gm.acceleration).all() and gm.dt > 0


json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-(10**6), 10**6), floats, st.text(max_size=8)),
    lambda children: st.one_of(
        st.lists(children, max_size=3), st.dictionaries(st.text(max_size=8), children, max_size=4)
    ),
    max_leaves=12,
)
sections = st.sampled_from(
    [
        "structure",
        "ground_motion",
        "preprocessor",
        "operator",
        "refiner",
        "data",
        "training",
        "output",
    ]
)
base = {
    "structure": {"name": "toy-structure"},
    "ground_motion": {"name": "toy-source"},
    "operator": {"name": "toy-operator"},
}


@given(
    data=st.dictionaries(sections, json_values, max_size=6),
    fields=st.dictionaries(st.text(max_size=8), json_values, max_size=3),
)
@settings(
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
def test_config_parsing_accepts_or_names_the_field(toy_registry, data, fields):
    for candidate in (
        data,
        {**base, **data},
        {**base, "operator": {"name": "toy-operator", **fields}},
    ):
        try:
            config = cp.parse_config(candidate)
        except cp.ConfigError as error:
            assert str(error)
            continue
        assert config.structure.name == "toy-structure"
