"""The condensed linear model of the SAC frame against the OpenSees model while no fibre
yields, and OpenSees continuing from its state."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from cphysfno_opensees.loader import import_opensees
from cphysfno_opensees.sac9 import analysis as sac9_analysis
from cphysfno_opensees.sac9 import phases as sac9_phases
from cphysfno_opensees.sac9.analysis import (
    SolverConfig,
    analyse_record,
    configure_solver,
)
from cphysfno_opensees.sac9.elastic import (
    elastic_centre,
    elastic_frame,
    elastic_response,
    first_step_beyond,
)
from cphysfno_opensees.sac9.model import FrameConfig, build_frame
from cphysfno_opensees.sac9.phases import ELASTIC_SHARE, elastic_start
from cphysfno_opensees.sac9.sections import HARDENING_RATIO, STEEL_MODULUS
from cphysfno_opensees.sac9.structure import Sac9Frame
from sac9_pulses import DAMPING, DT, pulse, relative

import cphysfno_core as cp
from cphysfno_core.plugin import Rayleigh

MODEL = FrameConfig()
PLAIN = SolverConfig(elastic_phases=False)
TIGHT = SolverConfig(
    test="NormDispIncr", tolerance=1e-12, algorithm=("Newton",), elastic_phases=False
)


@pytest.fixture(scope="module")
def condensed():
    return elastic_frame(MODEL, DAMPING)


def test_the_condensed_model_follows_opensees_while_no_fibre_yields(condensed):
    record = pulse(0.4)
    u, _, _ = elastic_response(condensed, record, DT)
    assert first_step_beyond(condensed, u, ELASTIC_SHARE) is None
    assert first_step_beyond(condensed, u, 0.5) is not None  # a record near yield
    opensees = analyse_record(MODEL, TIGHT, DAMPING, record, DT)
    assert relative(u, opensees) < 1e-5  # measured 2e-6: P-Delta of the axial forces


def test_its_fibre_stresses_are_those_of_opensees(condensed):
    """The end-section fibre stresses read from an OpenSees analysis at the step of the
    largest roof displacement against the condensed model's stress map."""
    record = pulse(0.4)
    u, _, _ = elastic_response(condensed, record, DT)
    peak = int(np.argmax(np.abs(u[:, -1])))
    ops = import_opensees()
    frame = build_frame(ops, MODEL)
    ops.rayleigh(DAMPING.mass_factor, 0.0, DAMPING.stiffness_factor, 0.0)
    ops.timeSeries("Path", 1, "-dt", DT, "-values", *record)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    configure_solver(ops, TIGHT)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    assert ops.analyze(peak, DT) == 0
    measured = np.concatenate(
        [
            np.reshape(ops.eleResponse(element, "section", point, "fiberData"), (-1, 5))[:, 3]
            for element, point in condensed.sections
        ]
        + [condensed.interior.stresses(ops)]
    )
    ops.wipe()
    assert {element for element, _ in condensed.sections} == set(frame.members)
    assert len(condensed.interior.sections) == 3 * len(frame.members)
    predicted = condensed.stress_map @ u[peak]
    # Measured 1e-3 of the largest: the P-Delta moments of the columns' axial forces, which
    # the linear model leaves out, well inside the margin below yield it keeps.
    assert np.max(np.abs(predicted - measured)) < 3e-3 * np.max(np.abs(measured))
    assert np.max(np.abs(measured) / condensed.yield_stress) > 0.5


def test_a_record_that_never_yields_needs_no_opensees_analysis(monkeypatch, condensed):
    def refuse(*args, **kwargs):
        raise AssertionError("OpenSees ran")

    monkeypatch.setattr(sac9_analysis, "transient_response", refuse)
    answer = analyse_record(MODEL, SolverConfig(), DAMPING, pulse(0.4), DT)
    assert np.array_equal(answer, elastic_response(condensed, pulse(0.4), DT)[0])


@pytest.mark.parametrize("interior", [True, False])
def test_opensees_continues_from_the_state_of_the_condensed_model(interior):
    model = dataclasses.replace(MODEL, elastic_interior=interior)
    record = pulse(1.0)
    start = elastic_start(model, DAMPING, record, DT)
    assert 20 < start.step < 150  # the frame yields during the pulse
    fast = analyse_record(model, SolverConfig(), DAMPING, record, DT)
    plain = analyse_record(model, PLAIN, DAMPING, record, DT)
    assert np.array_equal(fast[: start.step + 1], start.displacement)
    assert relative(fast, plain) < 1e-5


def with_rest(record: np.ndarray, seconds: float) -> np.ndarray:
    return np.concatenate([record, np.zeros(round(seconds / DT))])


@pytest.mark.parametrize("interior", [True, False])
def test_elastic_phases_after_a_yield_come_from_the_condensed_model(monkeypatch, interior):
    """The frame yields in the pulse and then vibrates freely, its fibres still near yield
    at the first peaks: OpenSees runs through the yielding, the condensed model takes most
    of the free vibration, and the answer is OpenSees'."""
    leaps: list[int] = []
    original = sac9_phases.ElasticLeaps.__call__

    def counted(self, steps_done):
        rows = original(self, steps_done)
        leaps.append(0 if rows is None else len(rows))
        return rows

    monkeypatch.setattr(sac9_phases.ElasticLeaps, "__call__", counted)
    model = dataclasses.replace(MODEL, elastic_interior=interior)
    record = with_rest(pulse(1.0), 6.0)
    fast = analyse_record(model, SolverConfig(), DAMPING, record, DT)
    plain = analyse_record(model, PLAIN, DAMPING, record, DT)
    assert sum(leaps) > 300  # of the 600 steps at rest (measured 400-500)
    assert relative(fast, plain) < 1e-5
    assert relative(fast[-600:], plain[-600:]) < 1e-5


def test_steel_stays_elastic_within_the_range_around_its_centre():
    """``Steel01`` in OpenSees, pushed past yield and back, then strained by increments
    inside and outside the range that ``elastic_centre`` gives."""
    ops = import_opensees()
    fy = 345.0e6
    path = [0.004, 0.002]

    def stress_after(strains: list[float]) -> tuple[float, float]:
        ops.wipe()
        ops.uniaxialMaterial("Steel01", 1, fy, STEEL_MODULUS, HARDENING_RATIO)
        ops.testUniaxialMaterial(1)
        for strain in strains:
            ops.setStrain(strain)
        return ops.getStress(), ops.getStrain()

    stress, strain = stress_after(path)
    centre = float(elastic_centre(stress, strain))
    assert 0.1 * fy < abs(centre) < fy  # yielded in tension, unloaded: the range has moved
    for share in (-0.99, -0.5, 0.5, 0.99, 1.01, 1.2, -1.01):
        increment = (share * fy - centre) / STEEL_MODULUS
        new_stress, _ = stress_after([*path, strain + increment])
        elastic = stress + STEEL_MODULUS * increment
        if abs(share) < 1.0:
            assert new_stress == pytest.approx(elastic, rel=1e-12)
        else:
            assert abs(new_stress) < abs(elastic) * (1 - 1e-4)
    ops.wipe()


def test_only_the_fibre_model_condenses():
    with pytest.raises(ValueError, match="fibre model"):
        elastic_frame(dataclasses.replace(MODEL, model="hinges"), Rayleigh(0.1, 0.01))


@pytest.mark.parametrize("model", ["fibre", "hinges"])
def test_the_frames_own_linear_system_has_its_opensees_periods(model):
    """The exact linear system (the model condensed to its floors, with the P-Delta of its
    weight) against OpenSees' eigen analysis; the paper's equivalent system (the pushover
    shear building) is another one."""
    frame = Sac9Frame(model=model)
    system = frame.linear_system()
    squares = np.sort(np.linalg.eigvals(np.linalg.solve(system.mass, system.stiffness)).real)
    np.testing.assert_allclose(2 * np.pi / np.sqrt(squares), frame.periods(), rtol=1e-6)
    if model == "fibre":
        np.testing.assert_allclose(system.stiffness, elastic_frame(MODEL, DAMPING).stiffness)
    exact = cp.create("preprocessor", "els-exact").fit(frame)
    np.testing.assert_array_equal(exact.system_.stiffness, system.stiffness)
    paper = cp.create("preprocessor", "els").fit(frame)  # the pushover's shear building
    assert np.allclose(paper.system_.stiffness, frame.equivalent_linear_system().stiffness)
    assert not np.allclose(paper.system_.stiffness, system.stiffness, rtol=0.05)
