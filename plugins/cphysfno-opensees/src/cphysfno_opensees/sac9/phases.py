"""The phases of an analysis of the SAC frame in which no steel yields, taken from the
exact condensed model of :mod:`~cphysfno_opensees.sac9.elastic` instead of OpenSees.

:func:`elastic_start` gives the response from rest up to the step before a fibre first
nears yield; :class:`ElasticLeaps` carries a running OpenSees analysis across the elastic
phases after a yield. :func:`~cphysfno_opensees.sac9.analysis.analyse_record` uses both.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from cphysfno_core.plugin import Rayleigh

from .elastic import (
    ElasticFrame,
    FloorState,
    elastic_frame,
    elastic_response,
    fibre_centres,
    first_step_beyond,
    newmark_floors,
    set_state,
)
from .model import FrameConfig

ELASTIC_SHARE = 0.99
"""Share of its elastic range up to which a fibre's stress is taken from the condensed
linear model (its stresses agree with the OpenSees model's to about 1e-3 of the largest:
the second-order P-Delta moments of the columns' axial forces)."""

SHORTEST_LEAP = 50
"""Fewest steps of an elastic phase worth taking from the condensed model after a yield."""

TRY_EVERY = 25
"""Steps of OpenSees between tries to take an elastic phase from the condensed model."""

LEAP_WINDOW = 256
"""Steps of an elastic phase computed at a time."""

SETTLING_STEPS = 10
"""Steps before the end of an elastic phase at which OpenSees takes over again, so that the
massless rotations, set from the condensed model, settle before any fibre nears yield."""


@dataclass(frozen=True)
class ElasticStart:
    """Where OpenSees takes over from the condensed linear model.

    Attributes:
        step: the last step taken from the linear model.
        displacement: ``[step + 1, 9]`` its floor displacements up to there, m.
        state: its Newmark state of the floors at ``step``.
        model: the condensed model.
    """

    step: int
    displacement: np.ndarray
    state: FloorState
    model: ElasticFrame


def elastic_start(
    frame_config: FrameConfig, damping: Rayleigh, acceleration: np.ndarray, dt: float
) -> ElasticStart:
    """The response of the condensed linear model of the (fibre) frame up to the step
    before a fibre first reaches :data:`ELASTIC_SHARE` of its yield stress, or to the end
    of the record if none does (then ``step`` is the last step).

    Args:
        frame_config: the fibre model (either interior).
        damping: Rayleigh coefficients.
        acceleration: ``[T]`` ground acceleration, m/s^2.
        dt: time step, s.
    """
    model = elastic_frame(frame_config, damping)
    u, v, a = elastic_response(model, np.asarray(acceleration, dtype=float), dt)
    first = first_step_beyond(model, u, ELASTIC_SHARE)
    step = len(u) - 1 if first is None else max(first - 1, 0)
    state = FloorState(u[step], v[step], a[step])
    return ElasticStart(step, u[: step + 1], state, model)


class ElasticLeaps:
    """Carries an OpenSees analysis of the fibre frame across the elastic phases after a
    yield with the condensed linear model (the ``leap`` of
    :func:`~cphysfno_opensees.transient.integrate`).

    While every fibre stays elastic, the floors obey the condensed model exactly, offset by
    the restoring force at the last OpenSees step: ``M u'' + C u' + K (u - u_k) = P(t) -
    P_k + M u''_k + C u'_k`` (the massless DOFs' equilibrium, damping included, keeps the
    offset constant). From the fibres' elastic centres now (:func:`fibre_centres`), the
    model finds the step at which a fibre would leave :data:`ELASTIC_SHARE` of its elastic
    range; if that is at least :data:`SHORTEST_LEAP` steps ahead, every node is set to the
    state :data:`SETTLING_STEPS` before it (floors exact, the massless DOFs from the
    condensed model, which OpenSees corrects at its next step) and the analysis continues
    from there; if not, the next try waits until OpenSees has passed that step.

    Args:
        ops: the OpenSees module, with the analysis running.
        model: the condensed model of the analysed frame.
        restart: starts the analysis again after a leap (the model's state set).
        acceleration: ``[T]`` the whole record, m/s^2.
        dt: time step, s.
        first: the step of the record at which the analysis started.
        floors: the floors' node tags.
    """

    def __init__(
        self,
        ops: Any,
        model: ElasticFrame,
        restart: Callable[[], None],
        acceleration: np.ndarray,
        dt: float,
        first: int,
        floors: list[int],
    ) -> None:
        self.ops, self.model, self.restart = ops, model, restart
        self.acceleration = np.asarray(acceleration, dtype=float)
        self.dt, self.first, self.floors = dt, first, floors
        self.next_try = first

    def __call__(self, steps_done: int) -> np.ndarray | None:
        ops, model = self.ops, self.model
        step = self.first + steps_done
        if step < self.next_try:
            return None
        if len(self.acceleration) - 1 - step < SHORTEST_LEAP + SETTLING_STEPS:
            return None
        centres = fibre_centres(ops, model)
        if np.any(np.abs(centres) >= ELASTIC_SHARE * model.yield_stress):
            return None
        u = np.array([ops.nodeDisp(node, 1) for node in self.floors])
        v = np.array([ops.nodeVel(node, 1) for node in self.floors])
        a = np.array([ops.nodeAccel(node, 1) for node in self.floors])
        du, dv, da = self._elastic_phase(step, FloorState(0.0 * u, v, a), centres)
        last = len(du) - 1
        if last < SHORTEST_LEAP:
            # A fibre nears yield within a few steps: OpenSees must take it there first.
            self.next_try = step + last + SETTLING_STEPS
            return None
        base = {node: np.asarray(ops.nodeDisp(node)) for node in model.node_map}
        set_state(ops, model, FloorState(du[last], dv[last], da[last]), base=base)
        ops.setTime((step + last) * self.dt)
        ops.wipeAnalysis()
        self.restart()
        return u + du[1 : last + 1]

    def _elastic_phase(
        self, step: int, state: FloorState, centres: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The floors' displacement increments, velocities and accelerations from ``step``
        (row 0) to :data:`SETTLING_STEPS` before a fibre leaves :data:`ELASTIC_SHARE` of
        its elastic range, or to the end of the record; computed a window at a time."""
        model, record = self.model, self.acceleration
        offset = model.masses * state.acceleration + model.damping @ state.velocity
        columns: tuple[list[np.ndarray], ...] = ([], [], [])
        done = step
        while True:
            ground = record[done : done + LEAP_WINDOW + 1] - record[step]
            window = newmark_floors(model, offset - np.outer(ground, model.masses), self.dt, state)
            beyond = first_step_beyond(model, window[0], ELASTIC_SHARE, centres)
            keep = len(window[0]) if beyond is None else beyond
            for column, part in zip(columns, window, strict=True):
                column.append(part[(0 if done == step else 1) : keep])
            done += len(window[0]) - 1
            if beyond is not None or done >= len(record) - 1:
                break
            state = FloorState(*(part[-1] for part in window))
        du, dv, da = (np.concatenate(column) for column in columns)
        if beyond is not None:
            keep = max(len(du) - SETTLING_STEPS, 1)
            du, dv, da = du[:keep], dv[:keep], da[:keep]
        return du, dv, da
