"""Central-difference (explicit Newmark) integration of a shear building with any story law.

The integrator of explicit structural dynamics (Newmark with ``beta = 0`` and
``gamma = 1/2``, as OpenSees' ``CentralDifference``): one evaluation of the story springs a
step, where classical Runge-Kutta takes four. With generalised coordinates ``q`` of unit
mass (:mod:`.chain`), a step ``h`` from ``(q, q', q'')``:

    q+ = q + h q' + h^2 / 2 q'',   w = q' + h / 2 q'',
    (I + h / 2 C) q''+ = -p a_g+ - C w - K q+ - B F(D q+, s+),   q'+ = w + h / 2 q''+.

The damping is taken implicitly, so the step is stable for ``omega_max h < 2`` whatever the
damping; it is of second order (the period of a mode of ``omega h`` is shortened by about
``(omega h)^2 / 24``). A story's law is driven by its drift increment over the step, at
the mean drift rate ``(v+ - v) / h``. A law with corners (one that settles) takes one
Euler step of its ``rate`` from the start of the step and then its ``settle`` at ``v+``: a
return mapping, exact along a branch of a piecewise-linear law, with the force put back on
the branch it reached within the step. A smooth law (``settle`` is
:func:`~.laws.common.no_settling`, as Bouc-Wen's) takes the midpoint rule, of second
order. The kernel has the argument list of :func:`.generic.rk4_kernel`'s.
"""

from __future__ import annotations

from functools import cache

import numba
import numpy as np
from cphysfno_core.plugin import LawFunctions

from .generic import FAST, story_value
from .laws.common import no_settling


@cache
def central_difference_kernel(functions: LawFunctions, n_states: int):
    """The compiled central-difference integrator of a building whose stories follow
    ``functions``."""
    force, rate, settle = functions
    width = max(n_states, 1)
    smooth = settle is no_settling

    @numba.njit(inline="always", **FAST)
    def accelerations(q, velocity, ag_now, solved, coupled, shear, out):
        """``out = (I + h/2 C)^-1 (-p a_g - C w - K q - B F)``, ``solved`` the products
        of that inverse with ``(p, C, K, B)``; ``coupled``: ``K`` is not zero."""
        part, damping, coupling, force_map = solved
        r, d = part.shape[0], shear.shape[0]
        for j in range(r):
            value = -part[j] * ag_now
            for m in range(r):
                value -= damping[j, m] * velocity[m]
            if coupled:
                for m in range(r):
                    value -= coupling[j, m] * q[m]
            for s in range(d):
                value -= force_map[j, s] * shear[s]
            out[j] = value

    @numba.njit(**FAST)
    def kernel(ag, chain, start, h, substeps, disp_out, drift_out, shear_out, finite_out):
        damping, coupling, force_map, drift_map, part, floors, coef = chain
        n_records, n_steps = ag.shape
        r, d = part.shape[0], drift_map.shape[0]
        solve = np.linalg.inv(np.eye(r) + 0.5 * h * damping)
        solved = (solve @ part, solve @ damping, solve @ coupling, solve @ force_map)
        coupled = np.any(coupling != 0.0)
        q = np.empty(r)
        velocity = np.empty(r)
        predicted = np.empty(r)
        acceleration = np.empty(r)
        states = np.empty((d, width))
        drift = np.empty(d)
        shear = np.empty(d)
        story_rate = np.zeros(width)
        half = np.zeros(width)
        for rec in range(n_records):
            q[:] = 0.0
            velocity[:] = 0.0
            states[:, :] = 0.0
            for s in range(d):
                for m in range(start.shape[1]):
                    states[s, m] = start[s, m]
            for s in range(d):
                drift[s] = 0.0
                shear[s] = force(coef[s], 0.0, states[s])
                disp_out[rec, 0, s] = 0.0
                drift_out[rec, 0, s] = 0.0
                shear_out[rec, 0, s] = shear[s]
            accelerations(q, velocity, ag[rec, 0], solved, coupled, shear, acceleration)
            for k in range(n_steps - 1):
                a0 = ag[rec, k]
                slope = (ag[rec, k + 1] - a0) / substeps
                for sub in range(substeps):
                    for j in range(r):
                        q[j] += h * velocity[j] + 0.5 * h * h * acceleration[j]
                        predicted[j] = velocity[j] + 0.5 * h * acceleration[j]
                    for s in range(d):
                        v = story_value(drift_map, q, s, 0)
                        state = states[s]
                        c = coef[s]
                        v_dot = (v - drift[s]) / h
                        rate(c, drift[s], v_dot, state, story_rate)
                        if smooth:
                            for m in range(width):
                                half[m] = state[m] + 0.5 * h * story_rate[m]
                            rate(c, 0.5 * (drift[s] + v), v_dot, half, story_rate)
                        for m in range(width):
                            state[m] += h * story_rate[m]
                        settle(c, v, state)
                        drift[s] = v
                        shear[s] = force(c, v, state)
                    ag_now = a0 + slope * (sub + 1)
                    accelerations(q, predicted, ag_now, solved, coupled, shear, acceleration)
                    for j in range(r):
                        velocity[j] = predicted[j] + 0.5 * h * acceleration[j]
                for s in range(d):
                    disp_out[rec, k + 1, s] = story_value(floors, q, s, 0)
                    drift_out[rec, k + 1, s] = drift[s]
                    shear_out[rec, k + 1, s] = shear[s]
            finite = True
            for j in range(r):
                finite &= np.isfinite(q[j]) and np.isfinite(velocity[j])
            finite_out[rec] = finite

    return kernel
