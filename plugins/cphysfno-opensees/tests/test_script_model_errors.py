"""``opensees-model``: what a user can get wrong, and the message that says so."""

from __future__ import annotations

import logging
import re

import numpy as np
import pytest
import script_models as sm
from cphysfno_opensees.script.source import ScriptError

import cphysfno_core as cp
from cphysfno_core import ConfigError, GroundMotions

GOOD_BUILD = """
import openseespy.opensees as ops


def build():
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 0.0, 3.0)
    ops.fix(1, 1, 1, 1)
    ops.mass(2, 1.0e4, 1.0e4, 0.0)
    ops.geomTransf("Linear", 1)
    ops.element("elasticBeamColumn", 1, 1, 2, 0.01, 2.0e11, 1.0e-4, 1)
"""

SERIES = '''
import openseespy.opensees as ops


def build():
    """A mass on two elastic-perfectly-plastic springs in series, of one strength: once they
    yield, the node between them has no stiffness, no mass and no damping."""
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.node(3, 0.0)
    ops.fix(1, 1)
    ops.mass(3, 1.0e3)
    ops.uniaxialMaterial("ElasticPP", 1, 1.0e7, 1.0e-3)
    ops.uniaxialMaterial("ElasticPP", 2, 1.0e6, 1.0e-2)
    ops.element("zeroLength", 1, 1, 2, "-mat", 1, "-dir", 1)
    ops.element("zeroLength", 2, 2, 3, "-mat", 2, "-dir", 1)
'''


def model(folder, name: str, text: str, **params):
    path = folder / f"{name}.py"
    path.write_text(text)
    return cp.create("structure", "opensees-model", script=str(path),
                     **{"outputs": [[2, 1]], **params})  # fmt: skip


@pytest.mark.parametrize(
    ("name", "text", "params", "message"),
    [
        ("raises", "raise RuntimeError('no license for this model')\n", {},
         r"raises\.py raised RuntimeError while it was executed: no license for this "
         r"model\n  raises\.py, line 1"),
        ("syntax", "def build(:\n", {}, r"syntax\.py raised SyntaxError"),
        ("nobuild", "import openseespy.opensees as ops\n", {},
         r"nobuild\.py defines no function build\(\)"),
        ("buildraises", "def build():\n    return 1 / 0\n", {},
         r"build\(\) of OpenSees script .*buildraises\.py raised ZeroDivisionError"),
        ("badnode", GOOD_BUILD + "    ops.element('elasticBeamColumn', 2, 2, 99, 0.01, "
         "2e11, 1e-4, 1)\n", {}, r"build\(\) of OpenSees script .*badnode\.py raised "
         r"OpenSeesError(.|\n)*OpenSees said:(.|\n)*99"),
        ("missing", GOOD_BUILD, {"outputs": [[2, 1], [7, 1]]},
         r"outputs: the model of OpenSees script .*missing\.py has no node 7"),
        ("dof", GOOD_BUILD, {"outputs": [[2, 5]]}, r"node 2 of OpenSees .* has DOFs 1 to 3"),
        ("fixed", GOOD_BUILD, {"outputs": [[1, 1]]}, r"DOF 1 of node 1 .* is restrained"),
        ("nogravity", GOOD_BUILD, {"gravity": "weights"},
         r"nogravity\.py defines no function weights\(\)"),
        ("modes", GOOD_BUILD, {"rayleigh_modes": [1, 3]}, r"rayleigh_modes = \[1, 3\]: .* 2 mode"),
        ("buckled", GOOD_BUILD.replace('"Linear"', '"PDelta"') + '''

def gravity():
    """Four times the cantilever's buckling load."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(2, 0.0, -2.2e7, 0.0)
''', {"gravity": "gravity"}, r"model of OpenSees script .*buckled\.py is unstable at its "
         r"gravity state"),
    ],
)  # fmt: skip
def test_a_bad_script_is_a_config_error_naming_it(tmp_path, name, text, params, message):
    structure = model(tmp_path, name, text, **params)
    with pytest.raises(ScriptError, match=message) as caught:
        structure.periods()
    assert isinstance(caught.value, ConfigError)


def test_a_gravity_analysis_that_fails_names_the_script(tmp_path):
    text = (
        SERIES
        + """

def gravity():
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(3, 2.0e4)  # twice what the springs carry
"""
    )
    structure = model(tmp_path, "overload", text, outputs=[[3, 1]], gravity="gravity",
                      rayleigh_modes=[1, 1])  # fmt: skip
    with pytest.raises(ScriptError, match=r"gravity analysis of OpenSees script .*overload\.py"
                       r" .* did not converge"):  # fmt: skip
        structure.periods()


def test_a_missing_script_is_a_config_error(tmp_path):
    structure = cp.create("structure", "opensees-model", script=str(tmp_path / "gone.py"),
                          outputs=[[2, 1]])  # fmt: skip
    with pytest.raises(ScriptError, match="gone.py: no such file"):
        structure.linear_system()


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"length_unit": "furlong"}, "length_unit"),
        ({"outputs": []}, "outputs"),
        ({"outputs": [[2, 1], [2, 1]]}, "each \\[node, dof\\] may appear once"),
        ({"outputs": [[2, 7]]}, "outputs"),
        ({"constraints": "Magic"}, "constraints"),
        ({"story_heights": [3.0, 3.0]}, "one per output"),
        ({"story_heights": [3.0], "drift_pairs": [[1, 2]]}, "not both"),
        ({"output_names": ["a", "b"]}, "output_names"),
        ({"rayleigh_modes": [0, 2]}, "counted from 1"),
        ({"gravity": "not a name"}, "gravity"),
    ],
)
def test_bad_parameters_fail_before_any_work(params, message):
    with pytest.raises(ConfigError, match=message):
        cp.create("structure", "opensees-model", script="model.py",
                  **{"outputs": [[2, 1]], **params})  # fmt: skip


def test_a_record_that_does_not_converge_collapsed_the_structure(tmp_path, caplog):
    """Two springs in series that yield at once leave the node between them without
    stiffness, mass or damping: no step converges past that instant. The record collapsed
    the model: its history holds up to the last step that converged, the cause is logged
    with the record's metadata, and OpenSees' complaints come back with the record."""
    structure = model(tmp_path, "series", SERIES, outputs=[[3, 1]], rayleigh_modes=[1, 1])
    motions = sm.records(n=3, peak=30.0, n_steps=101)
    scaled = np.array([1.0, 0.01, 1.0])[:, None] * motions.acceleration
    metadata = [{"rsn": 12, "scale": 1.5}, {"rsn": 13, "scale": 0.01}, {"rsn": 14, "scale": 1}]
    with caplog.at_level(logging.INFO, logger="cphysfno_opensees.structure"):
        responses = structure.simulate(GroundMotions(scaled, motions.dt, metadata))
    assert responses.failures == {}
    assert responses.collapsed.tolist() == [True, False, True]
    assert re.search(r"record 0 collapsed the structure: did not converge at t = .* "
                     r"\(rsn = 12, scale = 1.5\)", caplog.text)  # fmt: skip
    u = responses.displacement
    for i in (0, 2):
        stopped = int(np.argmax(np.isnan(u[i, :, 0])))
        assert stopped > 1 and np.isfinite(u[i, :stopped]).all() and np.isnan(u[i, stopped:]).all()
        assert "analyze failed" in responses.messages[i]
    assert np.isfinite(u[1]).all()
    one = structure.simulate(GroundMotions(scaled[:1], motions.dt)).displacement[0]
    np.testing.assert_array_equal(one, u[0])
