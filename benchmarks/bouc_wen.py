"""Data generation speed: the Bouc-Wen shear building of Example 1 on the fine grid.

Ours is ``BoucWenShearBuilding.simulate`` on 1000 paper white-noise records (3001 samples
at 0.01 s, five stories). The alternatives a user would otherwise pick, both one record
after another and timed on a subset scaled linearly to 1000 records:

- ``scipy.integrate.solve_ivp`` (RK45, rtol 1e-6) of the same equations, the ground
  acceleration linear between samples;
- OpenSeesPy: the same building as five ``zeroLength`` elements of the ``BoucWen``
  uniaxial material, modal damping of 5 % in every mode, Newmark average acceleration at
  the record's step.

Accuracy is relative L2 per story (the largest over the stories) against a tight reference
(DOP853, rtol 1e-10, one sample interval at a time) on a few of the same records.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.integrate
import scipy.linalg
from cphysfno_opensees.loader import import_opensees

import cphysfno_core as cp

from .common import Row, Timing, load_average, median_time, on_cores

MASS = 3.0e4
STIFFNESS = np.array([7.5e7, 7.0e7, 6.0e7, 4.5e7, 2.5e7])
ALPHA, EXPONENT, AMPLITUDE = 0.1, 3.0, 1.0
SHAPE = 1.0 / (2.0 * 0.01**EXPONENT)
DAMPING_RATIO = 0.05
COMPATIBILITY = np.eye(5) - np.eye(5, k=-1)


def run(quick: bool = False) -> list[Row]:
    n_records, n_alternative, n_reference = (20, 2, 1) if quick else (1000, 10, 3)
    runs = 2 if quick else 5
    motions = cp.create("ground_motion", "white-noise").sample(n_records, np.random.default_rng(0))
    building = cp.create("structure", "bouc-wen-shear-building")
    load_before = load_average()
    with on_cores(1):
        ours_one, ours_one_how = median_time(lambda: building.simulate(motions), runs=runs)
    ours_all, ours_all_how = median_time(lambda: building.simulate(motions), runs=runs)
    truth = building.simulate(motions[:n_alternative]).displacement
    references = [_reference(a, motions.dt) for a in motions.acceleration[:n_reference]]
    our_error = max(_relative_l2(truth[i], references[i]).max() for i in range(n_reference))
    scale = n_records / n_alternative
    subset = motions.acceleration[:n_alternative]
    with on_cores(1):
        ivp_seconds, ivp_how, ivp_u = _record_by_record(
            lambda a: _solve_ivp(a, motions.dt), subset, runs
        )
    try:
        ops = import_opensees()
    except cp.PluginError as error:
        ops, ops_seconds, ops_how, ops_notes = (
            None,
            None,
            None,
            [f"OpenSeesPy not importable ({error})"],
        )
    if ops is not None:
        with on_cores(1):
            ops_seconds, ops_how, ops_u = _record_by_record(
                lambda a: _opensees(ops, a, motions.dt, 1), subset, runs
            )
        ops_seconds *= scale
        ops_fine = _opensees(ops, motions.acceleration[0], motions.dt, 4)
        ops_notes = [
            f"OpenSees: {n_alternative} records per run, scaled x{scale:g}",
            f"OpenSees relative L2 to ours {_relative_l2(ops_u, truth).max():.1e} at dt "
            f"= {motions.dt} s and {_relative_l2(ops_fine, truth[0]).max():.1e} at dt/4 "
            "(Newmark is second order: the same system, converging)",
        ]
    load = f"load average {load_before} before, {load_average()} after"
    size = f"{n_records} x {motions.n_steps} x 5"
    accuracy = (
        f"ours: relative L2 per story (max over stories) {our_error:.1e} against DOP853 "
        f"rtol 1e-10 on {n_reference} records"
    )
    return [
        Row(
            stage=f"Bouc-Wen fine-grid simulate, {size}",
            ours_s=ours_one,
            ours_timing=ours_one_how,
            alternative="scipy solve_ivp RK45 rtol 1e-6, record by record",
            alternative_s=ivp_seconds * scale,
            alternative_timing=ivp_how,
            target="<= 0.2 s; >= 20 000x vs solve_ivp",
            notes=[
                accuracy,
                f"solve_ivp: {n_alternative} records per run, scaled x{scale:g}; its "
                f"relative L2 to ours {_relative_l2(ivp_u, truth).max():.1e}",
                load,
            ],
        ),
        Row(
            stage=f"Bouc-Wen fine-grid simulate, {size}",
            ours_s=ours_one,
            ours_timing=ours_one_how,
            alternative="OpenSeesPy BoucWen zeroLength, Newmark avg. accel. at dt, "
            "record by record",
            alternative_s=ops_seconds,
            alternative_timing=ops_how,
            target=">= 300x vs OpenSees",
            notes=[*ops_notes, load],
        ),
        Row(
            stage=f"Bouc-Wen fine-grid simulate on every core, {size}",
            ours_s=ours_all,
            ours_timing=ours_all_how,
            alternative="the same on one core (the rows above)",
            alternative_s=ours_one,
            alternative_timing=ours_one_how,
            target="report",
            notes=["the difference is the point: how the kernel scales with cores", load],
        ),
    ]


def _record_by_record(
    solve: Callable[[np.ndarray], np.ndarray], records: np.ndarray, runs: int
) -> tuple[float, Timing, np.ndarray]:
    """Median wall time in s of solving ``records`` one after another (``runs`` timed runs
    after one untimed run), how it was taken, and the ``[n, T, 5]`` displacements."""
    results = []

    def every_record() -> None:
        results.clear()
        results.extend(solve(record) for record in records)

    seconds, timing = median_time(every_record, runs=runs, warmup=1)
    return seconds, timing, np.stack(results)


def _relative_l2(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """``[5]`` relative L2 per story over every record and sample."""
    axes = tuple(range(truth.ndim - 1))
    return np.sqrt(((estimate - truth) ** 2).sum(axes) / (truth**2).sum(axes))


def _damping() -> np.ndarray:
    """``[5, 5]`` classical damping, 5 % in every elastic mode (N s/m)."""
    mass = MASS * np.eye(5)
    stiffness = COMPATIBILITY.T @ np.diag(STIFFNESS) @ COMPATIBILITY
    squares, modes = scipy.linalg.eigh(stiffness, mass)
    return mass @ modes @ np.diag(2.0 * DAMPING_RATIO * np.sqrt(squares)) @ modes.T @ mass


def _rates(y: np.ndarray, ground: float, damping: np.ndarray) -> np.ndarray:
    """Time derivative of ``[u, u', h]`` of the paper's equations at ground accel. ``ground``."""
    u, w, h = y[:5], y[5:10], y[10:]
    drift_rate = COMPATIBILITY @ w
    shear = STIFFNESS * (ALPHA * (COMPATIBILITY @ u) + (1.0 - ALPHA) * h)
    acceleration = -(COMPATIBILITY.T @ shear + damping @ w) / MASS - ground
    power = np.abs(h) ** (EXPONENT - 1.0)
    h_rate = drift_rate * (AMPLITUDE - SHAPE * power * np.abs(h)) - (
        SHAPE * np.abs(drift_rate) * power * h
    )
    return np.concatenate([w, acceleration, h_rate])


def _solve_ivp(ag: np.ndarray, dt: float) -> np.ndarray:
    """``[T, 5]`` floor displacements by one RK45 solve (rtol 1e-6, default atol) over the
    record."""
    damping = _damping()
    times = np.arange(ag.size) * dt

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return _rates(y, np.interp(t, times, ag), damping)

    solution = scipy.integrate.solve_ivp(
        rhs, (0.0, times[-1]), np.zeros(15), method="RK45", rtol=1e-6, t_eval=times
    )
    return solution.y[:5].T


def _reference(ag: np.ndarray, dt: float) -> np.ndarray:
    """``[T, 5]`` floor displacements by DOP853 (rtol 1e-10), one sample interval at a time
    so that the kinks of the piecewise-linear motion fall on interval ends."""
    damping = _damping()
    y = np.zeros(15)
    out = np.zeros((ag.size, 5))
    for k in range(ag.size - 1):
        slope = (ag[k + 1] - ag[k]) / dt

        def rhs(t, state, start=ag[k], slope=slope, t0=k * dt):
            return _rates(state, start + slope * (t - t0), damping)

        y = scipy.integrate.solve_ivp(
            rhs, (k * dt, (k + 1) * dt), y, method="DOP853", rtol=1e-10, atol=1e-13
        ).y[:, -1]
        out[k + 1] = y[:5]
    return out


def _opensees(ops, ag: np.ndarray, dt: float, substeps: int) -> np.ndarray:
    """``[T, 5]`` floor displacements of the building built in OpenSees.

    Story ``i`` is a ``zeroLength`` element of the ``BoucWen`` material: force
    ``alpha k_i u + (1 - alpha) k_i z`` with
    ``z' = u' (Ao - |z|^n (gamma + beta sgn(u' z)))`` and no degradation, which is the
    paper's law with ``Ao = A``, ``gamma = zeta`` and ``beta = delta``. Damping is 5 % in
    every mode of the initial stiffness (``modalDamping``).
    """
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(0, 0.0)
    ops.fix(0, 1)
    for story in range(1, 6):
        ops.node(story, 0.0, "-mass", MASS)
        k = float(STIFFNESS[story - 1])
        ops.uniaxialMaterial(
            "BoucWen", story, ALPHA, k, EXPONENT, SHAPE, SHAPE, AMPLITUDE, 0.0, 0.0, 0.0
        )
        ops.element("zeroLength", story, story - 1, story, "-mat", story, "-dir", 1)
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *ag)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", 1e-10, 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    ops.eigen("-fullGenLapack", 5)
    ops.modalDamping(DAMPING_RATIO)
    out = np.zeros((ag.size, 5))
    for k in range(1, ag.size):
        if ops.analyze(substeps, dt / substeps) != 0:
            raise RuntimeError(f"OpenSees analysis failed at sample {k}")
        out[k] = [ops.nodeDisp(story, 1) for story in range(1, 6)]
    return out
