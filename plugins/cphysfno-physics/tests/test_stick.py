"""The stick of a shear building whose story laws are known: it must find those laws, its
damping and periods, and respond as the building does."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from cphysfno_bouc_wen.shear_building import ShearBuilding
from cphysfno_physics import (
    Stick,
    StickCalibration,
    stick_calibration,
    stick_figures,
    stick_probes,
    stick_refinement,
)
from cphysfno_physics import stick as stick_module
from cphysfno_physics.stick_calibration import (
    LAW_SPACES,
    IndefiniteFloorStiffness,
    first_within_tie,
)
from cphysfno_physics.stick_probes import FOLLOWS

import cphysfno_core as cp
from cphysfno_core import CapabilityError, ConfigError, CphysfnoWarning, GroundMotions, create
from cphysfno_core.model.skipping import predict_skipping_failures
from cphysfno_core.plugin import Stories
from cphysfno_core.testing import check_preprocessor

FAST = {"cycle_amplitudes": (0.0025, 0.005, 0.01), "points_per_cycle": 40}
"""A shorter cyclic protocol than the default, which still drives every story past yield."""

EXACT = "runge-kutta"
"""The integrator of the buildings these sticks are fitted to: on it a stick that found
their laws responds as they do to 1e-3 (on central difference it is off by the
integrator's error, a few per cent under these white noises)."""

BILINEAR = {"name": "bilinear", "alpha": 0.05, "yield_displacement": (0.008, 0.01, 0.012)}
BOUC_WEN = {"name": "bouc-wen", "alpha": 0.1, "exponent": 3.0, "yield_displacement": 0.01}
SOFTENING = {"name": "bilinear", "alpha": -0.05, "yield_displacement": (0.008, 0.01, 0.012)}
"""A story law that falls past yield (P-Delta): zero shear at 21 yield drifts, beyond the
monotonic pushover's 3 % of roof drift (7.5 to 15 yield drifts)."""


def building(law: dict, **extra) -> ShearBuilding:
    return create(
        "structure",
        "shear-building",
        masses=(2.0e4, 2.0e4, 1.5e4),
        stiffnesses=(4.0e7, 3.0e7, 2.0e7),
        story_heights=(4.0, 3.0, 3.0),
        story_law=law,
        **extra,
    )


@pytest.fixture(scope="module")
def motions() -> GroundMotions:
    """Three 10-s white-noise records that drive the stories to about twice their yield drift."""
    rng = np.random.default_rng(0)
    return GroundMotions(3.0 * rng.standard_normal((3, 1001)), 0.01)


@pytest.fixture(scope="module")
def bilinear_building() -> ShearBuilding:
    return building(BILINEAR)


@pytest.fixture(scope="module")
def bilinear_stick(bilinear_building) -> Stick:
    return Stick(**FAST, integrator=EXACT).fit(bilinear_building)


@pytest.fixture(scope="module")
def bouc_wen_building() -> ShearBuilding:
    return building(BOUC_WEN, rayleigh_modes=(1, 3), damping_ratio=0.03)


@pytest.fixture(scope="module")
def bouc_wen_stick(bouc_wen_building) -> Stick:
    return Stick(**FAST, integrator=EXACT).fit(bouc_wen_building)


def relative_l2(z: np.ndarray, u: np.ndarray) -> np.ndarray:
    return np.sqrt(((z - u) ** 2).sum(axis=(0, 1)) / (u**2).sum(axis=(0, 1)))


def test_bilinear_laws_are_found_and_chosen(bilinear_stick):
    calibration = bilinear_stick.calibration_
    assert calibration.law == "bilinear"
    found = calibration.fits["bilinear"].parameters
    assert np.allclose(found["alpha"], 0.05, rtol=1e-3)
    assert np.allclose(found["yield_displacement"], BILINEAR["yield_displacement"], rtol=1e-3)
    assert max(calibration.fits["bilinear"].errors) < 1e-6
    # the other laws cannot follow a bilinear loop as closely
    assert min(calibration.fits["peak-oriented"].errors) > 1e-2
    assert np.allclose(calibration.stiffness, [4.0e7, 3.0e7, 2.0e7], rtol=1e-9)
    assert calibration.damping_ratio == pytest.approx(0.05)
    assert calibration.rayleigh_modes is None


def test_bouc_wen_laws_and_rayleigh_damping_are_found(bouc_wen_stick):
    calibration = bouc_wen_stick.calibration_
    assert calibration.law == "bouc-wen"
    found = calibration.fits["bouc-wen"].parameters
    default = 0.5 / 0.01**3.0  # beta = gamma = 1 / (2 u_y^n)
    for key, value in {"alpha": 0.1, "exponent": 3.0, "yield_displacement": 0.01}.items():
        assert np.allclose(found[key], value, rtol=1e-3), key
    assert np.allclose(found["beta"], default, rtol=1e-3)
    assert np.allclose(found["gamma"], default, rtol=1e-3)
    assert calibration.damping_ratio == pytest.approx(0.03)
    assert calibration.rayleigh_modes == (1, 3)
    # a whole exponent is kept whole: the kernel multiplies instead of taking a power
    assert found["exponent"] == [3.0, 3.0, 3.0]


def test_a_bouc_wen_exponent_between_whole_numbers_is_found_as_it_is():
    """Rounded to 2 or 3 the fit would miss the building's n = 2.5: it is not rounded."""
    structure = building({**BOUC_WEN, "exponent": 2.5})
    pushed = {"laws": ("bouc-wen",), "law_choice": "pushover", "refine_records": 0}
    found = Stick(**FAST, **pushed).fit(structure).calibration_.fits["bouc-wen"]
    assert np.allclose(found.parameters["exponent"], 2.5, rtol=1e-3)
    assert max(found.errors) < 1e-3


@pytest.mark.parametrize("which", ["bilinear", "bouc_wen"])
def test_the_stick_responds_as_the_building(which, motions, request):
    structure = request.getfixturevalue(f"{which}_building")
    stick = request.getfixturevalue(f"{which}_stick")
    u = structure.simulate(motions).displacement
    drift = np.abs(np.diff(u, axis=2, prepend=0.0)).max()
    assert drift > 0.012  # past every story's yield drift
    assert relative_l2(stick.transform(motions), u).max() < 1e-3
    periods = stick.calibration_.stick_periods
    assert np.allclose(periods, structure.periods(), rtol=1e-6)


def test_the_stick_conforms(bilinear_building):
    check_preprocessor(Stick(**FAST, laws=("bilinear",)), bilinear_building)


def test_the_calibration_goes_through_json_and_back(bilinear_stick):
    calibration = bilinear_stick.calibration_
    again = StickCalibration.from_dict(json.loads(json.dumps(calibration.to_dict())))
    assert again.shear_building() == calibration.shear_building()
    assert again.to_dict() == calibration.to_dict()


class LongFirstPeriod(ShearBuilding):
    """Reports a first period 20 % longer than its model's (as a frame's flexure would
    against its story springs)."""

    def periods(self, n=None):
        periods = super().periods(n).copy()
        periods[0] *= 1.2
        return periods


def test_stiffness_is_scaled_to_the_first_period_and_the_others_warn():
    structure = LongFirstPeriod(**building(BILINEAR).get_params())
    with pytest.warns(CphysfnoWarning, match=r"modes \[2, 3\] differ by more than 10%"):
        # unrefined: records would show the model's own first period, not the one reported
        stick = Stick(**FAST, laws=("bilinear",), coupling="none", refine_records=0).fit(structure)
    calibration = stick.calibration_
    assert calibration.coupling is None
    assert calibration.stiffness_scale == pytest.approx(1.0 / 1.44, rel=1e-9)
    assert calibration.stick_periods[0] == pytest.approx(structure.periods(1)[0], rel=1e-9)


COUPLING = ((1.2e7, -0.8e7, 0.2e7), (-0.8e7, 1.4e7, -0.6e7), (0.2e7, -0.6e7, 0.5e7))
"""A positive definite stiffness (N/m) between the floors beyond the stories next to each
other, as a frame's bending gives."""


@pytest.fixture(scope="module")
def frame_like() -> ShearBuilding:
    """A bilinear building whose floors are also coupled elastically: a frame's flexure."""
    return building(BILINEAR, coupling=COUPLING, rayleigh_modes=(1, 2))


def test_a_coupled_stick_has_the_structures_floor_stiffness_and_periods(frame_like):
    stick = Stick(**FAST, laws=("bilinear",)).fit(frame_like)
    calibration = stick.calibration_
    own = frame_like.linear_system().stiffness
    assert np.allclose(stick.stick_.linear_system().stiffness, own, rtol=1e-9, atol=1e-3)
    assert np.allclose(calibration.stick_periods, frame_like.periods(), rtol=1e-9)
    # its pushover is still the structure's: springs and coupling together
    for curve in (calibration.backbone, calibration.cyclic):
        shear = calibration.stick_shears(curve)
        assert np.abs(shear - curve.story_shear).max() < 1e-2 * np.abs(curve.story_shear).max()
    again = StickCalibration.from_dict(json.loads(json.dumps(calibration.to_dict())))
    assert np.array_equal(again.coupling, calibration.coupling)


def test_a_coupled_stick_is_a_frame_like_building_and_springs_alone_are_not(frame_like, motions):
    motions = GroundMotions(1.6 * motions.acceleration, motions.dt)
    u = frame_like.simulate(motions).displacement
    assert np.abs(np.diff(u, axis=2, prepend=0.0)).max() > 0.012  # past yield
    pushed = {**FAST, "laws": ("bilinear",), "integrator": EXACT, "refine_records": 0}
    coupled = Stick(**pushed).fit(frame_like)
    alone = Stick(**pushed, coupling="none").fit(frame_like)
    coupled, alone = coupled.transform(motions), alone.transform(motions)
    # the springs take the pushover's slopes and the coupling the rest of the floor
    # stiffness: a bilinear spring plus a linear share is again bilinear, so the stick is
    # the building itself; springs alone miss its higher modes by 5-12 % (refined on
    # records, by 2-5 %)
    assert relative_l2(coupled, u).max() < 1e-6
    assert relative_l2(alone, u).min() > 0.04


def test_both_forms_are_fitted_and_the_probes_choose_the_coupled_one(frame_like):
    calibration = Stick(**FAST, laws=("bilinear", "bouc-wen")).fit(frame_like).calibration_
    assert calibration.coupling is not None
    assert calibration.law == "bilinear"
    errors = calibration.dynamic_errors
    assert set(errors) == {
        "bilinear",
        "bouc-wen",
        "bilinear (springs alone)",
        "bouc-wen (springs alone)",
    }
    assert errors["bilinear"] < 1e-6 < 0.04 < errors["bilinear (springs alone)"]
    assert "Springs alone were kept" not in "\n".join(stick_figures.summary_lines(calibration))


def test_springs_alone_that_follow_the_structure_are_kept_as_the_cheaper_stick():
    """A tenth of the frame's flexure: springs alone follow the building within FOLLOWS
    under the probes, so they are kept although the coupled stick is the building itself."""
    weak = tuple(tuple(0.1 * value for value in row) for row in COUPLING)
    structure = building(BILINEAR, coupling=weak, rayleigh_modes=(1, 2))
    calibration = Stick(**FAST, laws=("bilinear",), refine_records=0).fit(structure).calibration_
    errors = calibration.dynamic_errors
    assert errors["bilinear"] < 1e-6 < errors["bilinear (springs alone)"] <= FOLLOWS
    assert calibration.coupling is None
    assert calibration.law == "bilinear"
    summary = "\n".join(stick_figures.summary_lines(calibration))
    assert "Springs alone were kept although the coupled stick was closer" in summary
    assert 'coupling = "floors"' in summary


def test_a_floor_stiffness_that_is_not_positive_definite_leaves_springs_alone(monkeypatch):
    structure = building(BILINEAR)
    unstable = -structure.linear_system().stiffness  # as a structure unstable at rest gives
    monkeypatch.setattr(stick_calibration, "floor_stiffness", lambda system, floors: unstable)
    with pytest.raises(IndefiniteFloorStiffness, match='coupling = "none"'):
        Stick(**FAST, laws=("bilinear",), coupling="floors").fit(structure)
    with pytest.warns(CphysfnoWarning, match="springs alone"):
        stick = Stick(**FAST, laws=("bilinear",)).fit(structure)
    assert stick.calibration_.coupling is None


def test_the_stick_of_a_plain_shear_building_has_no_coupling(bilinear_stick):
    assert bilinear_stick.calibration_.coupling is None
    assert bilinear_stick.stick_.get_params()["coupling"] is None


class PiersFromTheGround(ShearBuilding):
    """Its stories all rise from the ground, as a bridge's piers do."""

    def stories(self):
        return Stories((None,) * 3, (0, 1, 2), (4.0, 3.0, 3.0))


def test_stories_that_are_not_stacked_are_refused():
    structure = PiersFromTheGround(**building(BILINEAR).get_params())
    with pytest.raises(ConfigError, match="stories one above the other"):
        Stick(**FAST).fit(structure)


def test_a_structure_without_a_pushover_is_refused(toy):
    with pytest.raises(CapabilityError, match=r"preprocessor 'stick'.*'toy-building'.*pushover"):
        Stick().fit(toy)


def test_unknown_laws_are_refused(bilinear_building):
    with pytest.raises(ConfigError, match="stick.laws"):
        Stick(**FAST, laws=("linear",)).fit(bilinear_building)


def test_the_calibration_is_written_with_its_summary_and_figure(bilinear_stick, tmp_path):
    files = bilinear_stick.write_artifacts(tmp_path)
    assert sorted(p.name for p in files) == ["stick.json", "stick.png", "summary.md"]
    written = json.loads((tmp_path / "stick.json").read_text())
    assert written == json.loads(json.dumps(bilinear_stick.calibration_.to_dict()))
    summary = (tmp_path / "summary.md").read_text()
    assert "story law `bilinear`" in summary and "does not follow" not in summary
    assert (tmp_path / "stick.png").stat().st_size > 10_000


def test_a_stick_that_cannot_follow_the_structure_says_so(bilinear_building, tmp_path):
    # a peak-oriented law (reloading towards the largest drift) cannot follow kinematic
    # hardening's loops
    stick = Stick(**FAST, laws=("peak-oriented",), refine_records=0).fit(bilinear_building)
    worst = stick.calibration_.fits["peak-oriented"].worst
    stick.write_artifacts(tmp_path)
    summary = (tmp_path / "summary.md").read_text()
    assert worst > 0.10, worst
    assert f"misses the pushovers' story shear by {worst:.0%}" in summary


def test_a_softening_bilinear_law_is_found_and_chosen():
    calibration = Stick(**FAST).fit(building(SOFTENING)).calibration_
    assert calibration.law == "bilinear"
    found = calibration.fits["bilinear"].parameters
    assert np.allclose(found["alpha"], -0.05, rtol=1e-3)
    assert np.allclose(found["yield_displacement"], SOFTENING["yield_displacement"], rtol=1e-3)
    assert max(calibration.fits["bilinear"].errors) < 1e-6
    # the monotonic curve falls: the laws that cannot soften stay at alpha = 0 and miss it
    assert min(calibration.fits["peak-oriented"].parameters["alpha"]) >= 0.0
    assert min(calibration.fits["peak-oriented"].errors) > 1e-2


def test_a_softening_stick_that_collapses_says_so_and_gives_no_z_there():
    softening = building(SOFTENING)
    stick = Stick(**FAST).fit(softening)
    period = float(softening.periods()[0])
    t = np.arange(0.0, 20.0, 0.01)
    resonant = 30.0 * np.sin(2.0 * np.pi * t / period)
    motions = GroundMotions(np.stack([resonant, 0.01 * resonant]), 0.01)
    truth = softening.simulate(motions)
    assert truth.collapsed.tolist() == [True, False]  # the building itself collapses
    with pytest.warns(CphysfnoWarning, match=r"1 of 2 records \(first \[0\]\) drive a story"):
        z = stick.transform(motions)
    assert np.isnan(z[0, -1]).all() and np.isfinite(z[0, 0]).all()
    np.testing.assert_allclose(z[1], truth.displacement[1], rtol=1e-3, atol=1e-6)


def test_a_record_whose_stick_collapses_is_a_predicted_collapse_not_a_failure():
    """A composite on a softening stick: the record that collapses its stick comes back
    flagged ``collapsed`` (NaN), not as a record that could not be predicted."""
    softening = building(SOFTENING)
    weak = GroundMotions(0.5 * np.random.default_rng(2).standard_normal((4, 2000)), 0.01)
    u = softening.simulate(weak).displacement
    model = cp.compose(
        structure=softening,
        preprocessor=Stick(**FAST),
        operator=("fno", {"layers": 1, "modes": 4, "width": 4}),
    )
    model.fit(weak[:3], u[:3], validation=(weak[3:], u[3:]), epochs=1, progress=None)
    t = np.arange(0.0, 20.0, 0.01)
    resonant = 30.0 * np.sin(2.0 * np.pi * t / float(softening.periods()[0]))
    motions = GroundMotions(np.stack([resonant, 0.01 * resonant]), 0.01)
    with pytest.warns(CphysfnoWarning, match="the stick collapses"):
        responses, failures = predict_skipping_failures(model, motions)
    assert failures == {}
    assert responses.collapsed.tolist() == [True, False]
    assert np.isnan(responses.displacement[0]).all()
    assert np.isfinite(responses.displacement[1]).all()


def test_a_law_chosen_by_its_dynamic_response_is_the_buildings_own(tmp_path):
    """The stick of a Bouc-Wen building, its law chosen by the probe pulses: Bouc-Wen is
    recovered, and its stick is the building under the probes; the errors are kept with
    the calibration and shown in its summary."""
    structure = building(BOUC_WEN)
    stick = Stick(**FAST, law_choice="dynamic").fit(structure)
    calibration = stick.calibration_
    errors = calibration.dynamic_errors
    assert calibration.law == "bouc-wen" and set(errors) == set(calibration.fits)
    assert errors["bouc-wen"] < 1e-2 < min(e for law, e in errors.items() if law != "bouc-wen")
    again = StickCalibration.from_dict(json.loads(json.dumps(calibration.to_dict())))
    assert again.dynamic_errors == errors
    stick.write_artifacts(tmp_path)
    assert "chosen by its response to three probe pulses" in (tmp_path / "summary.md").read_text()
    assert stick.refit_params()["law_choice"] == "pushover"


def test_probe_pulses_drive_the_stick_to_the_drifts_asked():
    from cphysfno_physics.stick_probes import probe_motions, roof_drift_ratio

    calibration = Stick(**FAST).fit(building(BILINEAR)).calibration_
    motions = probe_motions(calibration, (0.005, 0.01))
    stick = create("structure", "shear-building", **calibration.shear_building())
    reached = roof_drift_ratio(stick, motions, float(calibration.backbone.heights.sum()))
    np.testing.assert_allclose(reached, [0.005, 0.01], rtol=1e-3)


def test_a_calibration_is_held_within_each_laws_alpha_bounds():
    law = {"alpha": (-0.7, -0.05, 1.0), "yield_displacement": (0.01, 0.01, 0.01)}
    softening = LAW_SPACES["bilinear"].held_within_fit({"name": "bilinear", **law})
    assert softening["alpha"] == (-0.5, -0.05, 0.99)
    hardening = LAW_SPACES["peak-oriented"].held_within_fit({"name": "peak-oriented", **law})
    assert hardening["alpha"] == (0.0, 0.0, 0.99)
    assert hardening["yield_displacement"] == law["yield_displacement"]


PINCHING = {
    "name": "pinching",
    "alpha": 0.05,
    "yield_displacement": (0.008, 0.01, 0.012),
    "pinch_x": 0.6,
    "pinch_y": 0.3,
    "beta_unload": 0.4,
}


CRACKED_PINCHING = {
    **PINCHING,
    "name": "cracked-pinching",
    "crack_share": 0.4,
    "crack_displacement": (0.002, 0.0025, 0.003),
    "crack_hysteresis": 0.5,
}


@pytest.mark.parametrize(
    ("law", "simpler"),
    [(PINCHING, "peak-oriented"), (CRACKED_PINCHING, "pinching")],
    ids=["pinching", "cracked-pinching"],
)
def test_pinching_laws_are_found_and_chosen(law, simpler):
    name = law["name"]
    calibration = Stick(**FAST).fit(building(law)).calibration_
    assert calibration.law == name
    found = calibration.fits[name].parameters
    for key, value in law.items():
        if key != "name":
            assert np.allclose(found[key], value, rtol=1e-3), key
    # a simpler law cannot follow the loops: no pinching (peak-oriented), no cracking
    assert min(calibration.fits[simpler].errors) > 1e-2


def test_a_tie_goes_to_the_law_listed_first():
    # 0.0995 is within 1 % plus 1e-3 of 0.100: a tie, which the first listed takes
    assert first_within_tie({"pinching": 0.100, "cracked-pinching": 0.0995}) == "pinching"
    assert first_within_tie({"pinching": 0.100, "cracked-pinching": 0.090}) == "cracked-pinching"
    assert first_within_tie({(1, "a"): 0.3, (0, "b"): 0.3}) == (1, "a")


def test_a_saved_stick_is_restored_without_pushing_the_structure_again(
    bilinear_stick, bilinear_building, motions, tmp_path, monkeypatch
):
    bilinear_stick.write_artifacts(tmp_path)

    def no_pushover(*args, **kwargs):
        raise AssertionError("the structure was pushed again")

    monkeypatch.setattr(bilinear_building, "story_pushover", no_pushover)
    restored = Stick(**FAST).restore(bilinear_building, tmp_path)
    np.testing.assert_array_equal(restored.transform(motions), bilinear_stick.transform(motions))
    with pytest.raises(AssertionError, match="pushed again"):  # nothing saved: it fits
        Stick(**FAST).restore(bilinear_building, tmp_path / "empty")


def test_the_stick_runs_on_central_difference_where_the_probes_allow_it(tmp_path):
    """By default the stick takes central difference when, under the probe pulses, it is
    within the tolerance of the same stick on Runge-Kutta: the error is kept with the
    calibration (and its JSON), shown in the summary, and passed on to a family's members;
    its transform is the shear building on that integrator."""
    structure = building(BILINEAR)
    stick = Stick(**FAST, laws=("bilinear",)).fit(structure)
    calibration = stick.calibration_
    assert calibration.integrator == "central-difference"
    assert 0.0 < calibration.integrator_error <= stick_probes.INTEGRATOR_TOLERANCE
    assert stick.stick_.get_params()["integrator"] == "central-difference"
    assert stick.refit_params()["integrator"] == "central-difference"
    again = StickCalibration.from_dict(json.loads(json.dumps(calibration.to_dict())))
    assert (again.integrator, again.integrator_error) == ("central-difference",
                                                         calibration.integrator_error)  # fmt: skip
    stick.write_artifacts(tmp_path)
    assert "Integrator: `central-difference`" in (tmp_path / "summary.md").read_text()
    motions = stick_probes.probe_motions(calibration, (0.01,))
    on_runge_kutta = dataclasses.replace(calibration, integrator=EXACT).building()
    reference = on_runge_kutta.simulate(motions).displacement
    assert 0.0 < relative_l2(stick.transform(motions), reference).max() < 0.02


def test_the_stick_stays_on_runge_kutta_beyond_the_tolerance_or_when_told(monkeypatch):
    structure = building(BILINEAR)
    monkeypatch.setattr(stick_module, "INTEGRATOR_TOLERANCE", 0.0)
    calibration = Stick(**FAST, laws=("bilinear",)).fit(structure).calibration_
    assert calibration.integrator == EXACT and calibration.integrator_error > 0.0
    told = Stick(**FAST, laws=("bilinear",), integrator=EXACT).fit(structure).calibration_
    assert told.integrator == EXACT and told.integrator_error is None


def test_a_calibration_saved_before_the_integrator_choice_stays_on_runge_kutta(bilinear_stick):
    document = bilinear_stick.calibration_.to_dict()
    del document["integrator"], document["integrator_error"]
    again = StickCalibration.from_dict(document)
    assert again.shear_building()["integrator"] == EXACT and again.integrator_error is None


def test_a_stick_that_is_the_building_is_not_refined(bilinear_stick):
    """The pushovers found the building's own laws: on the synthetic records held out the
    stick follows the building within FOLLOWS, so nothing is searched, the stick stays as
    fitted, and the summary says so."""
    refinement = bilinear_stick.calibration_.refinement
    assert refinement["accepted"] is False and refinement["refined"] is None
    assert "held_out_after" not in refinement
    assert refinement["fitted"] + refinement["held_out"] == refinement["records"] == 12
    assert refinement["held_out_before"] < 1e-3
    line = stick_figures.refinement_line(refinement)
    assert "checked on 12 synthetic records" in line and "nothing was refined" in line


def test_a_law_that_cannot_be_the_buildings_is_refined_on_records(motions, tmp_path, monkeypatch):
    """Bilinear springs for a Bouc-Wen building: the pushover fit misses the rounded loops;
    refined on the building's response to synthetic records, the stick is closer to it on
    the records held out, and on records it never saw (white noise); the refinement is
    kept with the calibration and shown in the summary."""
    structure = building(BOUC_WEN, rayleigh_modes=(1, 3), damping_ratio=0.03)
    alone = Stick(**FAST, laws=("bilinear",), integrator=EXACT, refine_records=0).fit(structure)
    refined = Stick(**FAST, laws=("bilinear",), integrator=EXACT).fit(structure)
    refinement = refined.calibration_.refinement
    assert alone.calibration_.refinement is None
    assert refinement["accepted"] is True
    assert refinement["held_out_after"] < refinement["held_out_before"]
    assert refinement["fitted_after"] < refinement["fitted_before"]
    # "before" is the pushover-fitted stick's relative L2 on the records held out
    records = stick_refinement.refinement_records(alone.calibration_, [0.0025, 0.005, 0.01], 12)
    held = records[[2, 5, 8, 11]]
    truth = structure.simulate(held).displacement
    pushed = alone.calibration_.building().simulate(held).displacement
    pooled = np.sqrt(np.sum((pushed - truth) ** 2) / np.sum(truth**2))
    assert refinement["held_out_before"] == pytest.approx(pooled, rel=1e-9)
    u = structure.simulate(motions).displacement
    before = relative_l2(alone.transform(motions), u).max()
    assert relative_l2(refined.transform(motions), u).max() < before
    stiffnesses = refined.stick_.get_params()["stiffnesses"]
    assert np.array_equal(stiffnesses, refined.calibration_.stiffness)
    again = StickCalibration.from_dict(json.loads(json.dumps(refined.calibration_.to_dict())))
    assert again.refinement == refinement
    refined.write_artifacts(tmp_path)
    summary = (tmp_path / "summary.md").read_text()
    assert "refined on 12 synthetic records" in summary and "does not follow" not in summary
    monkeypatch.setattr(stick_figures, "RESPONSE_WARNING", 0.5 * refinement["held_out_after"])
    refined.write_artifacts(tmp_path)
    assert (
        "does not follow this structure closely under records"
        in (tmp_path / "summary.md").read_text()
    )


def test_a_shape_the_backbone_cannot_mend_is_refitted_with_the_whole_law(
    bouc_wen_building, bouc_wen_stick
):
    """The Bouc-Wen stick of a Bouc-Wen building with its unloading share put wrong (0.15
    for 0.5): refining the stiffness, yield drift and alpha cannot mend it; refitting the
    whole law finds the share again (the whole exponent held), the building's own law,
    and the records held out choose it."""
    calibration = bouc_wen_stick.calibration_
    rows = stick_refinement.story_rows(calibration)
    assert rows[:, 3] == pytest.approx(3.0) and rows[:, 4] == pytest.approx(0.5, abs=1e-3)
    rows[:, 4] = 0.15
    wrong = stick_refinement.refined_member(calibration, rows)
    refined = stick_refinement.refine(
        bouc_wen_building, wrong, bouc_wen_stick.floors_, [0.0025, 0.005, 0.01], 12
    )
    refinement = refined.refinement
    by_refinement = refinement["held_out_by_refinement"]
    assert refinement["accepted"] and refinement["refined"] == "whole law"
    assert by_refinement["whole law"] < 1e-6 < 0.1 < by_refinement["backbone"]
    assert by_refinement["backbone"] < refinement["held_out_before"]
    found = stick_refinement.story_rows(refined)
    assert found[:, 3] == pytest.approx(3.0, abs=1e-6)
    assert found[:, 4] == pytest.approx(0.5, abs=1e-6)
    assert "the law's shape refitted too" in stick_figures.refinement_line(refinement)


def test_too_few_refinement_records_leave_the_pushover_fit_and_say_so(bilinear_building):
    with pytest.warns(CphysfnoWarning, match="too few to fit on some and check on the others"):
        stick = Stick(**FAST, laws=("bilinear",), refine_records=2).fit(bilinear_building)
    assert stick.calibration_.refinement is None


def test_a_refined_bouc_wen_yield_drift_keeps_its_saturation_at_the_yield_drift(bouc_wen_stick):
    """A yield factor rebuilds the law at the new yield drift with the same shape: the
    hysteretic part saturates there ((beta + gamma)^(-1/n)) and unloads alike."""
    calibration = bouc_wen_stick.calibration_
    rows = stick_refinement.story_rows(calibration)
    rows[:, 2] = np.log([2.0, 0.5, 1.0])
    before = calibration.fits["bouc-wen"].parameters
    after = stick_refinement.refined_member(calibration, rows).fits["bouc-wen"].parameters
    u_y = np.multiply(before["yield_displacement"], [2.0, 0.5, 1.0])
    assert after["yield_displacement"] == pytest.approx(u_y, rel=1e-12)
    exponent = np.asarray(after["exponent"])
    saturation = np.add(after["beta"], after["gamma"]) ** (-1.0 / exponent)
    assert saturation == pytest.approx(u_y, rel=1e-9)
    ratio = np.divide(after["beta"], after["gamma"])
    assert ratio == pytest.approx(np.divide(before["beta"], before["gamma"]), rel=1e-9)
    assert after["alpha"] == pytest.approx(before["alpha"]) and exponent == pytest.approx(3.0)


@pytest.mark.parametrize("name", sorted(LAW_SPACES))
def test_a_laws_shape_is_read_back_from_its_parameters(name):
    """``shape_of`` inverts ``parameters`` for the shape, story by story: Bouc-Wen's share
    is beta / (beta + gamma), the cracking drift's ratio is over the yield drift."""
    space = LAW_SPACES[name]
    shapes = [
        [low + (high - low) * fraction for low, high in space.shape_bounds]
        for fraction in (0.25, 0.6)
    ]
    stories = [
        space.parameters(0.1, u_y, shape) for u_y, shape in zip((0.01, 0.03), shapes, strict=True)
    ]
    parameters = {key: [story[key] for story in stories] for key in stories[0]}
    assert space.shape_of(parameters) == pytest.approx(np.reshape(shapes, (2, -1)), rel=1e-12)


def test_a_law_start_whose_story_test_overflows_loses_instead_of_stopping_the_fit(
    bilinear_building,
):
    """A Bouc-Wen start at a yield drift a millionth of a millimetre (a corner so sharp
    that the story test overflows, as a first guess from a strange curve can give) ends
    the least squares with that start's error infinite: the law loses, the fit goes on."""
    backbone = bilinear_building.story_pushover(cp.signals.monotonic_protocol(0.03))
    cyclic = bilinear_building.story_pushover(
        cp.signals.cyclic_protocol(FAST["cycle_amplitudes"], FAST["points_per_cycle"]),
        backbone.pattern,
    )
    stiffness = np.asarray(bilinear_building.params.stiffnesses)
    guess = (np.full(3, 0.9), np.full(3, 1e-9))
    fit = stick_calibration.fit_law(LAW_SPACES["bouc-wen"], (backbone, cyclic), stiffness, guess)
    assert fit.worst == np.inf


def test_a_refinement_without_its_ground_motions_says_what_to_install(monkeypatch):
    def missing(kind, name, **params):
        raise cp.RegistryError(f"unknown {kind} '{name}'; known {kind} names: none")

    monkeypatch.setattr(stick_refinement, "create", missing)
    with pytest.raises(ConfigError, match="install it or set refine_records = 0"):
        Stick(**FAST, laws=("bilinear",)).fit(building(BILINEAR))
