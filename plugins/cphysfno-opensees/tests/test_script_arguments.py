"""``opensees-model`` ``arguments``: keywords given to the script's ``build()`` and gravity
function, each the ones its signature accepts; the same model with those values baked into
the script and run directly in OpenSeesPy (script_models.direct_run); a random argument,
one draw a record."""

from __future__ import annotations

import numpy as np
import pytest
import script_models as sm
from cphysfno_opensees.script.source import ScriptError, accepted

import cphysfno_core as cp
from cphysfno_core import ConfigError, GroundMotions

PARAMETRISED = '''
import openseespy.opensees as ops

H = 3.0  # m


def build(fy={fy!r}, E={E!r}):
    """A P-Delta cantilever in kN and m whose bending yields (a Steel01 moment-curvature
    law of yield moment fy Z, kN m, and stiffness E I, kN m^2), 10 t on top."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 0.0, H)
    ops.fix(1, 1, 1, 1)
    ops.mass(2, 10.0, 10.0, 0.0)
    ops.geomTransf("PDelta", 1)
    ops.uniaxialMaterial("Elastic", 1, E * 0.01)
    ops.uniaxialMaterial("Steel01", 2, fy * 5.0e-4, E * 1.0e-4, 0.02)
    ops.section("Aggregator", 1, 1, "P", 2, "Mz")
    ops.beamIntegration("Lobatto", 1, 1, 3)
    ops.element("forceBeamColumn", 1, 1, 2, 1, 1)


def gravity(load={load!r}):
    """A vertical load on the top, kN; not analysed here."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(2, 0.0, -load, 0.0)
'''

DEFAULTS = {"fy": 345e3, "E": 2e8, "load": 100.0}
"""The script's defaults: kPa, kPa, kN."""

OUTPUT = [(2, 1)]


def script(folder, name: str = "cantilever", **defaults: float):
    """The parametrised cantilever's script with these defaults (the others
    :data:`DEFAULTS`)."""
    path = folder / f"{name}.py"
    path.write_text(PARAMETRISED.format(**{**DEFAULTS, **defaults}))
    return path


def cantilever(path, **arguments: float):
    """The structure of the script at ``path``, its gravity loads applied, with
    ``arguments``."""
    return cp.create("structure", "opensees-model", script=str(path), outputs=OUTPUT,
                     gravity="gravity", arguments=arguments)  # fmt: skip


@pytest.fixture(scope="module")
def parametrised(folder):
    return script(folder)


def test_the_arguments_are_the_values_run_directly_in_opensees(parametrised, folder):
    """The structure with ``arguments`` against OpenSeesPy run directly on the script with
    those values as its defaults: the same analysis, step for step (measured: 1e-15
    relative L2). The records yield the column (peak drift 1.5 %; 0.98 relative L2 from
    the nominal script's response)."""
    values = {"fy": 150e3, "E": 2.1e8, "load": 300.0}
    motions = sm.records(n=2, n_steps=201, peak=6.0)
    u = cantilever(parametrised, **values).simulate(motions).displacement
    baked = script(folder, "baked", **values)
    for i, record in enumerate(motions.acceleration):
        direct = sm.direct_run(baked, OUTPUT, record, motions.dt, gravity=True)
        assert np.all(sm.relative_l2(u[i], direct.displacement) < 1e-9)
    nominal = cantilever(parametrised).simulate(motions).displacement
    assert np.all(sm.relative_l2(nominal, u) > 0.5)  # the arguments changed the model


def test_the_gravity_function_gets_its_keyword(parametrised, folder):
    """``load`` reaches gravity() alone (build() does not take it): the period at the
    gravity state is OpenSees' eigen period of the script with that load."""
    loaded = cantilever(parametrised, load=500.0).periods()
    expected = sm.eigen_periods(script(folder, "heavy", load=500.0), 1, gravity=True)
    np.testing.assert_allclose(loaded[:1], expected, rtol=1e-9)
    assert loaded[0] > cantilever(parametrised, load=0.0).periods()[0] * 1.01  # P-Delta


def test_a_keyword_no_function_takes_is_refused_naming_it(parametrised):
    structure = cantilever(parametrised, fy=360e3, Fy=360e3)
    with pytest.raises(ScriptError, match=r"arguments: Fy: no parameter of build\(\) or "
                       r"gravity\(\) of OpenSees script .*cantilever\.py takes it; they take "
                       r"build\(fy, E\), gravity\(load\)"):  # fmt: skip
        structure.periods()


def test_a_function_with_kwargs_takes_every_keyword():
    def build(fy=1.0, **rest):
        return fy, rest

    def gravity(load, /, *, E=1.0):
        return load, E

    arguments = {"fy": 2.0, "E": 3.0, "load": 4.0}
    assert accepted(build, arguments) == arguments
    assert accepted(gravity, arguments) == {"E": 3.0}  # load is positional only


def test_an_argument_must_be_a_python_name_and_a_number():
    for arguments in ({"f.y": 1.0}, {"fy": "strong"}):
        with pytest.raises(ConfigError, match="arguments"):
            cp.create("structure", "opensees-model", script="model.py", outputs=OUTPUT,
                      arguments=arguments)  # fmt: skip


def test_a_random_argument_is_one_structure_a_record(parametrised, tmp_path):
    """``arguments.fy`` lognormal: each record's response is the structure built with its
    own draw, and another record's draw gives the record another response (the records
    take the column to drifts of 5 to 6 %)."""
    config = cp.parse_config(
        {
            "structure": {
                "name": "opensees-model",
                "script": str(parametrised),
                "outputs": [list(OUTPUT[0])],
                "gravity": "gravity",
                "arguments": {"fy": {"dist": "lognormal", "median": 250e3, "beta": 0.1}},
            },
            "ground_motion": {"name": "white-noise", "duration": 2.0, "spectral_intensity": 0.3},
            "preprocessor": [{"name": "els"}],
            "operator": {"name": "fno"},
            "data": {"n_train": 1, "n_val": 1, "n_test": 1, "executor": "serial"},
        }
    )
    cp.generate_dataset(config, tmp_path / "data.h5", progress=False)
    data = cp.load_dataset(tmp_path / "data.h5")
    assert data.param_names == ("arguments.fy",)
    assert data.params.shape == (3, 1) and len(np.unique(data.params)) == 3
    motions = GroundMotions(data.ag, data.dt)
    for j, (fy,) in enumerate(data.params):  # every record on record j's structure
        u = cantilever(parametrised, fy=fy).simulate(motions).displacement
        for i in range(3):
            if i == j:
                np.testing.assert_array_equal(data.u[i], u[i])
            else:
                assert np.all(sm.relative_l2(u[i], data.u[i]) > 0.05)  # measured: 0.1 to 0.8
