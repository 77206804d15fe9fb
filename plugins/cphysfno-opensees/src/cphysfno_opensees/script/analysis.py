"""One record's time-history analysis of a user's model (runs in a worker process).

:func:`analyse` is module level so that a :func:`functools.partial` of it, with the model
and its damping bound, is picklable and runs in the workers of
:func:`cphysfno_opensees.runner.run_records`.
"""

from __future__ import annotations

import numpy as np

from ..convergence import ConvergenceParams
from ..loader import import_opensees
from ..transient import AnalysisFailed, integrate
from .damping import DampingSetup
from .model import ModelSpec, build_model, start_transient, transient_test
from .responses import response_reader

ALGORITHM = ("Newton",)
"""The solution algorithm of every step (the fallbacks of
:func:`~cphysfno_opensees.transient.integrate` take over where it fails)."""


def analyse(
    spec: ModelSpec,
    damping: DampingSetup,
    convergence: ConvergenceParams,
    acceleration: np.ndarray,
    dt: float,
) -> np.ndarray:
    """The outputs' response to one ground motion, from rest at the gravity state.

    The model is built and brought to rest under its gravity loads (held constant); the
    record, converted into the model's length unit, excites it as a UniformExcitation
    along ``spec.excitation_dof``, linear between samples, and Newmark's average
    acceleration rule integrates it at ``dt`` with Newton iterations, a step that does not
    converge climbing the ladder ``convergence`` of
    :func:`~cphysfno_opensees.transient.integrate`.

    Args:
        spec: the model, its constraint handler chosen.
        damping: the damping commands set after gravity.
        convergence: the convergence ladder of a step that does not converge.
        acceleration: ``[T]`` ground acceleration, m/s^2.
        dt: its time step, s.

    Returns:
        ``[T, 2 n_outputs + n_responses]``: the displacements relative to the ground from
        the gravity state (m for translations, rad for rotations), then the accelerations
        relative to the ground (``nodeAccel``: m/s^2, rad/s^2), then each named response
        of ``spec.responses`` (its own unit, as OpenSees gives it times its scale).

    Raises:
        AnalysisFailed: a step that nothing could complete (a collapse), with the response
            before it (m, rad) as its ``history``.
    """
    ops = import_opensees()
    built = build_model(ops, spec)
    ground = np.asarray(acceleration, dtype=np.float64) / spec.metres_per_unit
    start_transient(ops, spec, damping, ground, dt)
    outputs = spec.outputs
    scale = np.where(built.translations, spec.metres_per_unit, 1.0)

    named = len(spec.responses)
    origin = np.concatenate([built.at_rest, np.zeros(len(outputs) + named)])
    scale = np.concatenate([np.tile(scale, 2), np.ones(named)])
    responses = response_reader(ops, spec.responses)

    def read() -> list[float]:
        return (
            [ops.nodeDisp(node, dof) for node, dof in outputs]
            + [ops.nodeAccel(node, dof) for node, dof in outputs]
            + responses()
        )

    try:
        recorded = integrate(
            ops,
            ground.size - 1,
            dt,
            read,
            algorithm=ALGORITHM,
            test=transient_test(spec),
            convergence=convergence,
        )
    except AnalysisFailed as failure:
        failure.history = (failure.history - origin) * scale
        raise
    finally:
        ops.wipe()
    return (recorded - origin) * scale
