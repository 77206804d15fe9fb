"""The SAC frame as a cphysfno structure: the conformance checks, its elastic dynamics
against an independent integration of its condensed model, the coarse grid, and the
preprocessors that use it."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_opensees.loader import import_opensees
from cphysfno_opensees.pushover import PushoverCurve, PushoverError
from cphysfno_opensees.sac9.model import build_frame
from cphysfno_opensees.sac9.structure import Sac9Frame

import cphysfno_core as cp
from cphysfno_core.signals import monotonic_protocol
from cphysfno_core.testing import check_structure, small_motions


def relative_l2(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per floor, over records and time."""
    axes = tuple(range(truth.ndim - 1))
    return np.sqrt(((estimate - truth) ** 2).sum(axes) / (truth**2).sum(axes))


def condensed_stiffness(frame: Sac9Frame) -> tuple[np.ndarray, np.ndarray]:
    """``[9, 9]`` lateral stiffness (N/m) of the floors, inverted from static unit loads in
    OpenSees, and the ``[9]`` floor masses (kg)."""
    ops = import_opensees()
    flexibility = np.zeros((9, 9))
    for j in range(9):
        model = build_frame(ops, frame.frame_config)
        ops.timeSeries("Constant", 1)
        ops.pattern("Plain", 1, 1)
        ops.load(model.floors[j], 1.0, 0.0, 0.0)
        ops.constraints("Transformation")
        ops.numberer("Plain")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", 1e-16, 5)
        ops.algorithm("Linear")
        ops.integrator("LoadControl", 1.0)
        ops.analysis("Static")
        assert ops.analyze(1) == 0
        flexibility[:, j] = [ops.nodeDisp(node, 1) for node in model.floors]
    ops.wipe()
    return np.linalg.inv(flexibility), model.masses


def newmark(mass: np.ndarray, stiffness: np.ndarray, ag: np.ndarray, dt: float) -> np.ndarray:
    """``[T, n]`` undamped response of ``M u'' + K u = -M 1 a_g`` from rest by Newmark's
    average acceleration rule."""
    m = np.diag(mass)
    u, v = np.zeros(mass.size), np.zeros(mass.size)
    a = np.linalg.solve(m, -mass * ag[0] - stiffness @ u)
    effective = stiffness + 4.0 / dt**2 * m
    out = np.zeros((ag.size, mass.size))
    for k in range(1, ag.size):
        load = -mass * ag[k] + m @ (4.0 / dt**2 * u + 4.0 / dt * v + a)
        new = np.linalg.solve(effective, load)
        new_v = 2.0 / dt * (new - u) - v
        a = 4.0 / dt**2 * (new - u) - 4.0 / dt * v - a
        u, v = new, new_v
        out[k] = u
    return out


@pytest.fixture(scope="module")
def frame() -> Sac9Frame:
    return Sac9Frame(model="hinges")


@pytest.mark.parametrize("model", ["fibre", "hinges"])
def test_the_frame_conforms(model):
    check_structure(Sac9Frame(model=model))


def test_undamped_elastic_response_matches_the_condensed_model():
    frame = Sac9Frame(model="hinges", damping_ratio=0.0, p_delta=False)
    raw = small_motions(n_records=1, n_steps=201, dt=0.01, peak=0.02)
    # OpenSees starts from zero acceleration: the record must start at zero as well.
    motions = cp.GroundMotions(raw.acceleration * np.hanning(raw.n_steps), raw.dt)
    stiffness, masses = condensed_stiffness(frame)
    expected = newmark(masses, stiffness, motions.acceleration[0], motions.dt)
    u = frame.simulate(motions).displacement[0]
    assert relative_l2(u, expected).max() < 1e-6


def test_fibre_model_runs_a_short_record():
    motions = small_motions(n_records=1, n_steps=201, dt=0.01, peak=3.0)
    responses = Sac9Frame().simulate(motions)
    assert responses.failures == {}
    assert np.isfinite(responses.displacement).all()
    assert np.abs(responses.displacement).max() > 1e-3


def test_relaxed_by_name_follows_the_fine_response(frame):
    motions = small_motions(n_records=1, n_steps=301, dt=0.01, peak=0.5)
    fine = frame.simulate(motions).displacement
    relaxed = cp.create("preprocessor", "relaxed", factor=3).fit(frame)
    z = relaxed.transform(motions)  # the frame on the 0.03 s grid, interpolated back
    assert z.shape == fine.shape
    assert relative_l2(z, fine).max() < 0.05


def test_a_coarse_step_shorter_than_the_motion_is_refused(frame):
    with pytest.raises(cp.InputError, match="at least the motion's dt"):
        frame.simulate(small_motions(), dt=0.001)


def test_modal_reduction_of_the_frame_is_the_linear_modal_truncation_of_its_own_system(frame):
    """The frame has no restoring force to project: modal on all nine modes is els-exact."""
    motions = small_motions(n_records=1, n_steps=201, dt=0.01, peak=0.5)
    full = cp.create("preprocessor", "modal", modes=9).fit(frame).transform(motions)
    exact = cp.create("preprocessor", "els-exact").fit(frame).transform(motions)
    assert np.all(relative_l2(full, exact) < 1e-8)


def test_equivalent_linear_system_is_the_pushover_shear_building(frame):
    system = frame.equivalent_linear_system()
    k = frame.pushover().story_stiffness
    assert np.allclose(np.diag(system.stiffness, 1), -k[1:])
    assert np.allclose(np.diag(system.mass), frame.pushover().masses)
    squares = np.linalg.eigvals(np.linalg.solve(system.mass, system.stiffness))
    first = 2.0 * np.pi / np.sqrt(np.sort(squares.real)[0])
    assert first == pytest.approx(frame.periods(1)[0], rel=0.02)


def test_pushover_goes_well_past_yield_and_is_computed_once(frame):
    curve = frame.pushover()
    assert frame.pushover() is curve
    yield_drift = curve.roof_drift_ratio[curve.elastic_points - 1]
    assert 0.003 < yield_drift < 0.015
    assert curve.roof_drift_ratio[-1] >= 2.5 * yield_drift


def test_the_pushover_travels_with_reports_as_json_and_figure(frame, tmp_path):
    document, figure = frame.write_artifacts(tmp_path / "structure")
    saved = PushoverCurve.from_json(document.read_text())
    assert np.array_equal(saved.story_stiffness, frame.pushover().story_stiffness)
    assert figure.suffix == ".png" and figure.stat().st_size > 10_000


def test_a_pushover_too_short_to_yield_is_an_error():
    short = Sac9Frame(model="hinges", pushover_drift=0.002)
    with pytest.raises(PushoverError, match="stayed elastic"):
        short.equivalent_linear_system()


def test_els_by_name_is_close_to_the_frame_at_small_amplitude(frame):
    motions = small_motions(n_records=1, n_steps=301, dt=0.01, peak=0.01)
    els = cp.create("preprocessor", "els").fit(frame)
    z = els.transform(motions)
    u = frame.simulate(motions).displacement
    error = relative_l2(z, u)
    # the shear building holds the frame's first mode (its period within 1 %) but not its
    # flexural higher modes: measured 0.14 (level 2) down to 0.03 (level 8) on this record.
    assert error.max() < 0.2


def test_the_frame_has_its_own_linear_system_and_the_papers_equivalent_one(frame):
    """ELS uses the equivalent one (the pushover's shear building), els-exact the frame's."""
    assert frame.capabilities == {
        "linear_system",
        "equivalent_linear_system",
        "coarse_simulation",
        "stories",
        "pushover",
    }
    own, paper = frame.linear_system(), frame.equivalent_linear_system()
    assert not np.allclose(own.stiffness, paper.stiffness, rtol=0.05)
    np.testing.assert_allclose(np.diag(own.mass), np.diag(paper.mass), rtol=1e-9)


def test_the_story_pushover_starts_on_the_frames_condensed_stiffness(frame):
    """At 0.01 % roof drift the frame is elastic: the floors' displacements under the
    pushover's load are K^-1 F of the stiffness inverted from unit loads in OpenSees, and
    the first-mode pattern is that of the frame's own linear system; past yield the story
    shear levels off."""
    curves = frame.story_pushover(monotonic_protocol(0.02, 40))
    stiffness, masses = condensed_stiffness(frame)
    np.testing.assert_allclose(curves.masses, masses, rtol=1e-9)
    small = frame.story_pushover(np.array([0.0, 1e-4]))
    loads = small.story_shear[1, 0] * small.pattern  # the base shear times the pattern
    expected = np.diff(np.linalg.solve(stiffness, loads), prepend=0.0)
    np.testing.assert_allclose(small.story_drift[1], expected, rtol=1e-4)
    np.testing.assert_allclose(small.pattern, curves.pattern, rtol=1e-12)
    assert not curves.stopped and curves.story_drift.shape == (40, 9)
    secant = curves.story_shear[-1, 0] / curves.story_drift[-1, 0]
    assert secant < 0.8 * curves.initial_stiffness[0]  # the first story has yielded
