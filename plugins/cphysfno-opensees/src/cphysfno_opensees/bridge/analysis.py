"""One nonlinear time-history analysis of the bridge (runs in a worker process)."""

from __future__ import annotations

import os

import numpy as np

from cphysfno_core.plugin import Rayleigh

from ..loader import import_opensees
from ..transient import integrate
from .design import BridgeDesign
from .model import TRANSVERSE, Columns, ElasticSection, build
from .numerics import Numerics

EXCITATION_SERIES, EXCITATION_PATTERN = 2, 2


def analyse(
    design: BridgeDesign,
    numerics: Numerics,
    damping: Rayleigh,
    columns: Columns,
    elastic: ElasticSection | None,
    acceleration: np.ndarray,
    dt: float,
) -> np.ndarray:
    """Transverse column-top displacements of the bridge under one ground motion.

    The model is built and brought to rest under gravity; the record excites it across
    the girder (UniformExcitation in Y, linear between samples) and Newmark's average
    acceleration rule integrates it from rest, ``numerics.substeps`` steps per sample, a
    step that does not converge climbing the ladder ``numerics.convergence``.

    Args:
        design, numerics, damping, columns, elastic: the model (see
            :func:`cphysfno_opensees.bridge.model.build`) and its Rayleigh damping
            (``alphaM`` and ``betaKinit`` in OpenSees).
        acceleration: ``[T]`` ground acceleration, m/s^2.
        dt: its time step, s.

    Returns:
        ``[T, 10]`` displacements relative to the ground (m), measured from the gravity
        state, column by column in the order of ``Layout.column_tops``.

    Raises:
        AnalysisFailed: a step did not converge.
    """
    ops = import_opensees()
    ops.logFile(os.devnull, "-noEcho")
    where = build(ops, design, numerics, columns, elastic)
    tops = where.column_tops

    def read() -> list[float]:
        return [ops.nodeDisp(node, TRANSVERSE) for node in tops]

    at_rest = np.asarray(read())
    ops.rayleigh(damping.mass_factor, 0.0, damping.stiffness_factor, 0.0)
    values = np.asarray(acceleration, dtype=np.float64)
    ops.timeSeries("Path", EXCITATION_SERIES, "-dt", dt, "-values", *values)
    ops.pattern("UniformExcitation", EXCITATION_PATTERN, TRANSVERSE, "-accel", EXCITATION_SERIES)
    ops.constraints("Plain")
    ops.numberer(numerics.numberer)
    ops.system(numerics.system)
    test = ("NormDispIncr", numerics.tolerance, numerics.max_iterations)
    ops.test(*test)
    ops.algorithm(*numerics.algorithm)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    k = numerics.substeps
    steps = integrate(
        ops,
        k * (values.size - 1),
        dt / k,
        read,
        algorithm=numerics.algorithm,
        test=test,
        convergence=numerics.convergence,
    )
    return steps[::k] - at_rest
