"""The physics of a family from a few fitted members: the calibration surface interpolates
exactly what it should, a stick made from it matches the stick fitted to the member, and a
run on ``[uncertainty] physics = "surface"`` trains and predicts on the same physics."""

import warnings

import numpy as np
import pytest
from cphysfno_physics.stick import Stick
from tiny_family_run import tiny_config

import cphysfno_core as cp
from cphysfno_core.config.calibration_surface import CalibrationSurface, fit_surface
from cphysfno_core.config.uncertainty import with_values


def _surface(function, centre, below, above):
    """The surface of ``function(x [k]) -> [m]`` from its 2 k + 1 members."""
    k = len(centre)

    def along(i, value):
        x = np.array(centre, dtype=float)
        x[i] = value
        return function(x)

    return CalibrationSurface(
        {"name": "stick"}, tuple(f"p{i}" for i in range(k)), np.array(centre, float),
        np.array(below, float), np.array(above, float),
        {"numbers": [0.0, 0.0]}, ("numbers.0", "numbers.1"), function(np.array(centre, float)),
        np.array([along(i, below[i]) for i in range(k)]),
        np.array([along(i, above[i]) for i in range(k)]),
    )  # fmt: skip


def _additive(x):
    """Two numbers, one positive (quadratic in its logarithm along each parameter), one that
    changes sign (quadratic along each)."""
    positive = np.exp(0.3 + 0.5 * x[0] - 0.2 * x[0] ** 2 + 0.1 * x[1] + 0.05 * x[1] ** 2)
    signed = -0.4 + 0.8 * x[0] + 0.3 * x[0] ** 2 - 0.6 * x[1]
    return np.array([positive, signed])


def test_a_surface_is_exact_for_numbers_additive_and_quadratic_in_each_parameter():
    surface = _surface(_additive, [0.0, 1.0], [-1.0, 0.5], [2.0, 3.0])
    assert surface.logged.tolist() == [True, False]
    for x in ([0.0, 1.0], [-1.0, 0.5], [1.3, 2.2], [-0.7, 2.9], [2.0, 0.5]):
        np.testing.assert_allclose(
            surface.numbers_at(np.array(x)), _additive(np.array(x)), rtol=1e-12
        )


def test_beyond_its_outer_members_a_surface_goes_on_along_its_tangent():
    surface = _surface(_additive, [0.0, 1.0], [-1.0, 0.5], [2.0, 3.0])
    edge, step = 2.0, 0.5
    slope_log = 0.5 - 0.4 * edge  # d/dx of the positive number's logarithm at the edge
    slope = 0.8 + 0.6 * edge
    found = surface.numbers_at(np.array([edge + step, 1.0]))
    at_edge = _additive(np.array([edge, 1.0]))
    assert found[0] == pytest.approx(at_edge[0] * np.exp(slope_log * step), rel=1e-12)
    assert found[1] == pytest.approx(at_edge[1] + slope * step, rel=1e-12)


def test_a_surface_survives_its_document():
    surface = _surface(_additive, [0.0, 1.0], [-1.0, 0.5], [2.0, 3.0])
    again = CalibrationSurface.from_dict(surface.to_dict())
    x = np.array([0.4, 1.7])
    np.testing.assert_array_equal(again.numbers_at(x), surface.numbers_at(x))
    assert surface.calibration_at({"p1": 1.7}) == {
        "numbers": list(surface.numbers_at(np.array([0.0, 1.7])))
    }
    with pytest.raises(cp.ConfigError, match="spans p0, p1, not p2"):
        surface.calibration_at({"p2": 1.0})


TABLE = {
    "masses": [4.0e4, 3.0e4],
    "stiffnesses": [4.0e7, 3.0e7],
    "story_law": {"name": "bilinear", "alpha": 0.05, "yield_displacement": 0.015},
}
NAMES = ("stiffnesses.0", "story_law.yield_displacement")


def _member(values):
    return cp.create("structure", "shear-building", **with_values(TABLE, values))


@pytest.fixture(scope="module")
def stick_surface():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cp.CphysfnoWarning)
        return fit_surface(
            {"name": "stick", "laws": ["bilinear", "bouc-wen"]}, _member({}), NAMES,
            [3.0e7, 0.01], [5.5e7, 0.022],
        )  # fmt: skip


def _motions():
    rng = np.random.default_rng(3)
    return cp.GroundMotions(3.0 * rng.standard_normal((3, 600)), 0.01)


def _refit(surface, values):
    spec = {k: v for k, v in surface.preprocessor.items() if k != "name"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cp.CphysfnoWarning)
        return Stick(**spec).fit(_member(values))


def test_the_members_share_the_nominal_sticks_law(stick_surface):
    nominal = Stick(laws=["bilinear", "bouc-wen"]).fit(_member({}))
    law = nominal.calibration()["stick"]["story_law"]["name"]
    assert stick_surface.preprocessor["laws"] == [law]
    assert stick_surface.reference["stick"]["story_law"]["name"] == law


@pytest.mark.parametrize(
    ("values", "tolerance"),
    [
        ({"stiffnesses.0": 3.0e7}, 1e-12),  # an outer member: exact
        ({"story_law.yield_displacement": 0.022}, 1e-12),
        ({"stiffnesses.0": 3.5e7, "story_law.yield_displacement": 0.018}, 0.03),
        ({"stiffnesses.0": 6.0e7, "story_law.yield_displacement": 0.025}, 0.03),
    ],
)
def test_a_stick_from_the_surface_is_the_stick_fitted_to_the_member(
    stick_surface, values, tolerance
):
    motions = _motions()
    member = _member(values)
    fast = stick_surface.preprocessor_at(member, values).transform(motions)
    fitted = _refit(stick_surface, values).transform(motions)
    error = np.linalg.norm(fast - fitted) / np.linalg.norm(fitted)
    assert error <= tolerance


def test_a_stick_made_from_its_own_calibration_is_that_stick():
    fitted = Stick(laws=["bilinear"]).fit(_member({}))
    again = Stick(laws=["bilinear"]).calibrated(_member({}), fitted.calibration())
    motions = _motions()
    np.testing.assert_array_equal(again.transform(motions), fitted.transform(motions))
    wrong = {**fitted.calibration(), "floors": [0]}
    with pytest.raises(
        cp.ConfigError, match="floors for 1 outputs; structure 'shear-building' has 2"
    ):
        Stick(laws=["bilinear"]).calibrated(_member({}), wrong)
    with pytest.raises(cp.ConfigError, match="holds 'stick' and 'floors'.*got floors"):
        Stick(laws=["bilinear"]).calibrated(_member({}), {"floors": [0, 1]})


def test_a_calibration_past_the_laws_bounds_is_held_within_them():
    calibration = Stick(laws=["pinching"]).fit(_member({})).calibration()
    law = calibration["stick"]["story_law"]
    stick = {
        **calibration["stick"],
        "story_law": {**law, "pinch_y": [1.3, -0.2], "alpha": [1.5, 0.02]},
    }
    pushed = {**calibration, "stick": stick}
    held = (
        Stick(laws=["pinching"]).calibrated(_member({}), pushed).calibration()["stick"]["story_law"]
    )
    assert held["pinch_y"] == [1.0, 0.05]
    assert held["alpha"] == [0.99, 0.02]
    assert held["yield_displacement"] == law["yield_displacement"]


def test_members_that_choose_otherwise_are_refused(monkeypatch):
    own = Stick.calibration

    def marked(self):
        found = own(self)
        return {**found, "branch": "stiff" if found["stick"]["stiffnesses"][0] > 4.5e7 else "soft"}

    monkeypatch.setattr(Stick, "calibration", marked)
    with pytest.raises(cp.ConfigError, match=r"member at stiffnesses.0 = 5.5e\+07 differs"):
        fit_surface({"name": "stick", "laws": ["bilinear"]}, _member({}), NAMES[:1], [3e7], [5.5e7])


def test_a_preprocessor_without_calibration_has_no_surface():
    assert fit_surface({"name": "els"}, _member({}), NAMES[:1], [3e7], [5.5e7]) is None
    with pytest.raises(cp.CapabilityError, match="'els' has no calibration"):
        cp.create("preprocessor", "els").calibrated(_member({}), {})


RUN = """
preprocessor = { name = "stick", laws = ["bilinear"], cycle_amplitudes = [0.005, 0.01] }

[structure]
name = "shear-building"
masses = [4.0e4, 3.0e4]
stiffnesses = [{ dist = "lognormal", median = 4e7, beta = 0.2, unit = "N/m" }, 3e7]
story_law = { name = "bilinear", alpha = 0.05, yield_displacement = 0.01 }

[uncertainty]
physics = "surface"

"""


@pytest.fixture(scope="module")
def surface_run(tmp_path_factory):
    from cphysfno_core.app import pipeline

    folder = tmp_path_factory.mktemp("surface-run")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cp.CphysfnoWarning)
        return folder, pipeline.run(tiny_config(RUN), folder)


def test_a_run_on_the_surface_trains_and_predicts_on_the_same_physics(surface_run):
    folder, _ = surface_run
    data = cp.load_dataset(folder / "dataset.h5")
    surface = CalibrationSurface.from_dict(data.calibration_surfaces["stick"])
    assert surface.names == ("stiffnesses.0",)
    assert surface.below[0] == pytest.approx(4e7 * np.exp(-0.4))
    model = cp.CompositeModel.load(folder / "models" / "c-physfno-stick")
    assert model.calibration_surface.to_dict() == surface.to_dict()
    drawn = data.parameter_draws("test")
    z = model.physics(data.motions("test"), params=drawn)
    np.testing.assert_allclose(z, data.physics("stick", "test"), rtol=1e-10, atol=1e-14)
    first = {"stiffnesses.0": float(drawn["stiffnesses.0"][0])}
    refit = _refit(surface, first).transform(data.motions("test")[:1])
    error = np.linalg.norm(z[:1] - refit) / np.linalg.norm(refit)
    assert 0.0 < error < 0.03


def test_a_fixed_structures_stick_is_fitted_once_for_every_chunk(tmp_path, monkeypatch):
    fits = []
    own_fit = Stick.fit
    monkeypatch.setattr(Stick, "fit", lambda self, s: fits.append(s) or own_fit(self, s))
    head = RUN.replace(
        '[{ dist = "lognormal", median = 4e7, beta = 0.2, unit = "N/m" }, 3e7]', "[4e7, 3e7]"
    ).replace('[uncertainty]\nphysics = "surface"\n', "")
    config = tiny_config(head)
    config = config.model_copy(update={"data": config.data.model_copy(update={"chunk_size": 4})})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cp.CphysfnoWarning)
        cp.generate_dataset(config, tmp_path / "d.h5", progress=False)
        data = cp.load_dataset(tmp_path / "d.h5")
        assert len(fits) == 1
        structure = cp.create("structure", config.structure.name, **config.structure.params)
        spec = config.preprocessor[0].params
        expected = Stick(**spec).fit(structure).transform(data.motions("test"))
    np.testing.assert_array_equal(data.physics("stick", "test"), expected)
