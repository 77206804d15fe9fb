"""Classical fourth-order Runge-Kutta integration of a reduced model on the motion's grid.

The compiled kernel holds :data:`LANES` records side by side, records in the innermost
(SIMD) position: a Runge-Kutta stage is one loop over those records whose body evaluates
the whole reduced model of one record with its state in registers, which LLVM turns into
vector instructions. Blocks of records are spread over the cores in threads. The model's
sizes and a whole-number Bouc-Wen exponent are compile-time constants of the kernel
(:func:`.native.size_marker`; one compiled version per combination, cached on disk), so
its loops unroll and ``|h|^(n-1)`` costs a few multiplications instead of ``pow``. The
outputs of a block are kept for :data:`WINDOW` samples and then written record by record,
in long runs of consecutive memory.
"""

from __future__ import annotations

import numba
import numpy as np
from cphysfno_core.signals import run_in_slices

from .native import JIT, bouc_wen_rate, local_array, size_marker, whole_power
from .reduced import ReducedModel

LANES = 32
"""Records integrated together by one SIMD loop (two AVX-512 or four AVX2 float32 vectors,
which keeps independent work in flight while one vector waits on its dependency chain)."""

NODES = np.array([0.0, 0.5, 0.5, 1.0])
"""Times of the classical Runge-Kutta stages, as fractions of the step."""

WEIGHTS = np.array([1.0, 2.0, 2.0, 1.0]) / 6.0
"""Weights of the stages."""

STAGES = len(NODES)
"""State buffers of one step: the state, then where each later Runge-Kutta stage starts."""

WINDOW = 64
"""Samples of a block's outputs kept before they are written out, record by record."""


def integrate_rk4(
    model: ReducedModel,
    ground_acceleration: np.ndarray,
    dt: float,
    substeps: int,
    precision: type[np.floating] = np.float64,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Response of a building at rest at t = 0 to ground accelerations linear between samples.

    Args:
        model: the (reduced) building.
        ground_acceleration: ``[n, T]`` a_g in m/s^2, sampled every ``dt``.
        dt: sample spacing in s.
        substeps: Runge-Kutta steps per sample interval.
        precision: ``numpy.float32`` or ``numpy.float64``, the arithmetic of the kernel
            (float32 does twice as many records per instruction).

    Returns:
        Floor displacements ``[n, T, d]`` (m, float64), story drifts ``[n, T, d]`` (m) and
        story shears ``[n, T, d]`` (N) at the samples, these two in ``precision`` (they
        carry no more digits than the arithmetic, and float32 halves the memory they
        take), and ``[n]`` whether each record stayed finite.
    """
    ag = np.ascontiguousarray(ground_acceleration, dtype=precision)
    n_records, n_steps = ag.shape
    r, d = model.n_coordinates, model.n_stories
    displacement = np.empty((n_records, n_steps, d))
    drift, shear = (np.empty((n_records, n_steps, d), precision) for _ in range(2))
    finite = np.empty(n_records, dtype=np.bool_)
    h = dt / substeps
    fractions = (np.arange(substeps)[:, None] + NODES) / substeps
    stages = np.array([WEIGHTS * h, np.append(NODES[1:], 0.0) * h])
    power = float(model.exponent) - 1.0
    arrays = (
        model.stiffness,
        model.damping,
        model.hysteretic,
        model.drift,
        model.participation,
        model.floors,
        model.alpha * model.story_stiffness,
        (1.0 - model.alpha) * model.story_stiffness,
        fractions,
        stages,
    )
    coefficients = [np.ascontiguousarray(c, dtype=precision) for c in arrays] + [
        precision(x) for x in (model.a, model.delta, model.zeta, power)
    ]
    sizes = (size_marker(r), size_marker(d), size_marker(2 * r + d), whole_power(power))

    def kernel(rows: slice) -> None:
        outputs = (displacement[rows], drift[rows], shear[rows], finite[rows])
        _rk4_kernel(ag[rows], *coefficients, *sizes, *outputs)

    run_in_slices(kernel, n_records, LANES)
    return displacement, drift, shear, finite


@numba.njit(**JIT)
def _rk4_kernel(
    ag,
    stiffness,
    damping,
    hysteretic,
    drift,
    participation,
    floors,
    elastic_shear,
    hysteretic_shear,
    fractions,
    stages,
    a,
    delta,
    zeta,
    power,
    coordinates,
    stories,
    states,
    whole_power,
    displacement_out,
    drift_out,
    shear_out,
    finite_out,
):
    """Integrate the records of ``ag [n, T]`` and write the outputs ``[n, T, d]``, ``[n]``.

    The model's arrays are those of :class:`.ReducedModel`; story shears are
    ``elastic_shear * v + hysteretic_shear * h`` (N/m, ``[d]`` each). ``fractions``
    ``[substeps, 4]`` are the times of the stages of each Runge-Kutta step as fractions of a
    sample interval;
    ``stages [2, 4]`` holds each stage's weight times the step h, and how far (s) along its
    rates the next stage starts. ``coordinates``, ``stories`` and ``states`` are size
    markers of r, d and 2 r + d. The arithmetic is that of ``ag``'s dtype.
    """
    n_records, n_steps = ag.shape
    r, d, n_states = len(coordinates), len(stories), len(states)
    dtype = ag.dtype
    kappa = local_array((coordinates,), dtype)
    damp = local_array((coordinates, coordinates), dtype)
    hyst = local_array((coordinates, stories), dtype)
    drift_map = local_array((stories, coordinates), dtype)
    floor_map = local_array((stories, coordinates), dtype)
    part = local_array((coordinates,), dtype)
    shear_map = local_array((2, stories), dtype)
    for i in range(r):
        kappa[i] = stiffness[i]
        part[i] = participation[i]
        for j in range(r):
            damp[i, j] = damping[i, j]
        for s in range(d):
            hyst[i, s] = hysteretic[i, s]
            drift_map[s, i] = drift[s, i]
            floor_map[s, i] = floors[s, i]
    for s in range(d):
        shear_map[0, s] = elastic_shear[s]
        shear_map[1, s] = hysteretic_shear[s]
    model = (kappa, damp, hyst, drift_map, part, a, delta, zeta, power, whole_power)
    stage = local_array((STAGES, states, LANES), dtype)
    total = local_array((states, LANES), dtype)
    window = np.empty((WINDOW, 2, d, LANES), dtype)
    state = stage[0]
    block_ag = np.zeros((n_steps, LANES), dtype)
    for first in range(0, n_records, LANES):
        count = min(LANES, n_records - first)
        for lane in range(count):
            for k in range(n_steps):
                block_ag[k, lane] = ag[first + lane, k]
        state[:] = 0
        outputs = (first, count, shear_map, displacement_out, drift_out, shear_out)
        _keep_sample(state, window[0], floor_map, shear_map)
        for k in range(n_steps - 1):
            for sub in range(fractions.shape[0]):
                step_ag = (block_ag, k, fractions[sub])
                _stage(stage, 0, total, stages, step_ag, model, states)
                _stage(stage, 1, total, stages, step_ag, model, states)
                _stage(stage, 2, total, stages, step_ag, model, states)
                _stage(stage, 3, total, stages, step_ag, model, states)
            kept = (k + 1) % WINDOW
            if kept == 0:
                _write_window(window, k + 1 - WINDOW, WINDOW, outputs)
            _keep_sample(state, window[kept], floor_map, shear_map)
        start = (n_steps - 1) // WINDOW * WINDOW
        _write_window(window, start, n_steps - start, outputs)
        for lane in range(count):
            finite = True
            for i in range(n_states):
                finite &= np.isfinite(state[i, lane])
            finite_out[first + lane] = finite


@numba.njit(inline="always", **JIT)
def _stage(stage, i, total, stages, step_ag, model, states):
    """Runge-Kutta stage ``i`` (a literal, 0 to 3) of every lane.

    Evaluates the rates ``f`` at ``stage[i]`` ``[2r + d, LANES]`` with ``a_g`` at the
    stage's time in sample interval ``k`` (``step_ag = (block_ag, k, fractions [4])``), then
    accumulates ``total = sum of weight f`` over the stages and starts the next stage at
    ``stage[i + 1] = stage[0] + step f``; the last stage's target is the state
    ``stage[0]`` itself, which it advances by the step's ``total``, so a step ends without
    a separate pass over the state.

    All buffers are parts of one stack array, at offsets that never overlap, which lets
    LLVM vectorise the loop over the lanes without run-time alias checks.
    """
    kappa, damp, hyst, drift_map, part, a, delta, zeta, power, whole_power = model
    r, d = kappa.shape[0], drift_map.shape[0]
    block_ag, k, fractions = step_ag
    weight, step, fraction = stages[0, i], stages[1, i], fractions[i]
    rate = local_array((states,), stage.dtype)
    source, base, target = stage[i], stage[0], stage[(i + 1) % STAGES]
    for lane in range(LANES):
        ground = block_ag[k, lane] + fraction * (block_ag[k + 1, lane] - block_ag[k, lane])
        for j in range(r):
            rate[j] = source[r + j, lane]
        for j in range(r):
            force = kappa[j] * source[j, lane] + part[j] * ground
            for m in range(r):
                force += damp[j, m] * source[r + m, lane]
            for s in range(d):
                force += hyst[j, s] * source[2 * r + s, lane]
            rate[r + j] = -force
        for s in range(d):
            drift_rate = drift_map[s, 0] * source[r, lane]
            for m in range(1, r):
                drift_rate += drift_map[s, m] * source[r + m, lane]
            rate[2 * r + s] = bouc_wen_rate(
                drift_rate, source[2 * r + s, lane], a, delta, zeta, power, whole_power
            )
        for j in range(2 * r + d):
            if i == 0:
                total[j, lane] = weight * rate[j]
            else:
                total[j, lane] += weight * rate[j]
            if i == STAGES - 1:
                target[j, lane] = base[j, lane] + total[j, lane]
            else:
                target[j, lane] = base[j, lane] + step * rate[j]


@numba.njit(inline="always", **JIT)
def _keep_sample(state, kept, floor_map, shear_map):
    """Floor displacements (m) and hysteretic story shears (N) of a block's lanes,
    ``kept [2, d, LANES]``, from their state."""
    r, d = floor_map.shape[1], floor_map.shape[0]
    for lane in range(LANES):
        for s in range(d):
            floor = floor_map[s, 0] * state[0, lane]
            for j in range(1, r):
                floor += floor_map[s, j] * state[j, lane]
            kept[0, s, lane] = floor
            kept[1, s, lane] = shear_map[1, s] * state[2 * r + s, lane]


@numba.njit(inline="always", **JIT)
def _write_window(window, start, length, outputs):
    """Write samples ``start`` to ``start + length`` of a block's records from ``window``:
    floor displacements, story drifts (their differences, in float64) and story shears.

    Record after record, so that each output is written in runs of ``length * d``
    consecutive values (writing every sample of the block's records as it comes touches
    ``3 LANES`` distant places at a time and took several times as long).
    """
    first, count, shear_map, displacement_out, drift_out, shear_out = outputs
    d = window.shape[2]
    for lane in range(count):
        record = first + lane
        for kept in range(length):
            below = 0.0
            for s in range(d):
                floor = np.float64(window[kept, 0, s, lane])
                displacement_out[record, start + kept, s] = floor
                drift_out[record, start + kept, s] = floor - below
                shear_out[record, start + kept, s] = (
                    shear_map[0, s] * (floor - below) + window[kept, 1, s, lane]
                )
                below = floor
