"""The condensed linear model of the SAC frame against the OpenSees model while no fibre
yields, and OpenSees continuing from its state."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from cphysfno_opensees import sac9_analysis
from cphysfno_opensees.loader import import_opensees
from cphysfno_opensees.sac9_analysis import (
    ELASTIC_SHARE,
    Rayleigh,
    SolverConfig,
    analyse_record,
    configure_solver,
    elastic_start,
)
from cphysfno_opensees.sac9_elastic import elastic_frame, elastic_response, first_yield_step
from cphysfno_opensees.sac9_model import FrameConfig, build_frame

DT = 0.01
DAMPING = Rayleigh.matching(2.0 * np.pi / 2.37, 2.0 * np.pi / 0.51, 0.03)
MODEL = FrameConfig()
PLAIN = SolverConfig(elastic_start=False)
TIGHT = SolverConfig(
    test="NormDispIncr", tolerance=1e-12, algorithm=("Newton",), elastic_start=False
)


def pulse(amplitude: float) -> np.ndarray:
    """One sine cycle of 1.5 s and ``amplitude`` m/s^2, then 0.5 s at rest (dt 0.01 s)."""
    t = np.arange(201) * DT
    return amplitude * np.sin(2.0 * np.pi * t / 1.5) * (t < 1.5)


def relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.fixture(scope="module")
def condensed():
    return elastic_frame(MODEL, DAMPING.mass, DAMPING.stiffness)


def test_the_condensed_model_follows_opensees_while_no_fibre_yields(condensed):
    record = pulse(0.4)
    u, _, _ = elastic_response(condensed, record, DT)
    assert first_yield_step(condensed, u, ELASTIC_SHARE) is None
    assert first_yield_step(condensed, u, 0.5) is not None  # a record near yield
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
    ops.rayleigh(DAMPING.mass, 0.0, DAMPING.stiffness, 0.0)
    ops.timeSeries("Path", 1, "-dt", DT, "-values", *record)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    configure_solver(ops, TIGHT)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    assert ops.analyze(peak, DT) == 0
    measured = []
    for element in sorted(frame.yield_stresses):
        for point in (1, len(ops.eleResponse(element, "integrationPoints"))):
            fibres = np.reshape(ops.eleResponse(element, "section", point, "fiberData"), (-1, 5))
            y = np.abs(fibres[:, 0])
            measured.extend(fibres[y >= y.max() * (1 - 1e-12), 3])
    ops.wipe()
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


def test_only_the_fibre_model_condenses():
    with pytest.raises(ValueError, match="fibre model"):
        elastic_frame(dataclasses.replace(MODEL, model="hinges"), 0.1, 0.01)
