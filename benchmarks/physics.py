"""Speed and accuracy of the physics preprocessors ``els``, ``modal`` (r = 2) and ``relaxed``
(k = 30) on 1000 paper white-noise records (3001 samples at 0.01 s) and the Example 1
Bouc-Wen building.

- ``els`` beside ``scipy.signal.lsim`` of the same linear system, record by record (timed on
  a subset, scaled linearly to all records), with its largest error relative to lsim.
- ``modal`` beside the same preprocessor integrating the reduced model in NumPy from the
  structure's restoring force (the path for structures without ``projected_simulation``).
- ``modal`` and ``relaxed`` with the fine-grid nonlinear simulation as context, and their
  relative L2 to it per story.
"""

from __future__ import annotations

import numpy as np
import scipy.signal

import cphysfno_core as cp
from cphysfno_core.plugin import LinearSystem, Structure
from cphysfno_core.reporting import metrics

from .common import Row, load_average, median_time, on_cores


def run(quick: bool = False) -> list[Row]:
    n_records, n_lsim, n_accuracy = (20, 4, 10) if quick else (1000, 100, 100)
    motions = cp.create("ground_motion", "white-noise").sample(n_records, np.random.default_rng(0))
    building = cp.create("structure", "bouc-wen-shear-building")
    runs = 2 if quick else 5
    load_before = load_average()
    truth = building.simulate(motions[:n_accuracy]).displacement
    preprocessors = {
        name: cp.create("preprocessor", name).fit(building) for name in ("els", "modal", "relaxed")
    }
    with on_cores(1):  # like with like: every alternative here runs on one core
        fine, fine_how = median_time(lambda: building.simulate(motions), runs=runs)
        ours = {
            name: median_time(lambda p=p: p.transform(motions), runs=runs)
            for name, p in preprocessors.items()
        }
        lsim_seconds, lsim_how = median_time(
            lambda: _lsim(building.linear_system(), motions[:n_lsim]), runs=runs
        )
        generic_seconds, generic_how = median_time(
            _generic_modal(building, motions), runs=max(1, runs // 2), warmup=1
        )
    lsim_z = _lsim(building.linear_system(), motions[:n_lsim])
    els_z = preprocessors["els"].transform(motions[:n_lsim])
    els_error = np.max(np.abs(els_z - lsim_z), axis=(1, 2)) / np.max(np.abs(lsim_z), axis=(1, 2))
    accuracy = {
        name: metrics.relative_l2(preprocessors[name].transform(motions[:n_accuracy]), truth)
        for name in ("els", "modal", "relaxed")
    }
    load = f"load average {load_before} before, {load_average()} after"
    size = f"{n_records} x {motions.n_steps} x 5"
    scale = n_records / n_lsim

    def l2(name: str) -> str:
        values = ", ".join(f"{v:.3f}" for v in accuracy[name])
        return f"relative L2 to the fine-grid truth per story ({n_accuracy} records): {values}"

    return [
        Row(
            stage=f"els, {size}",
            ours_s=ours["els"][0],
            ours_timing=ours["els"][1],
            alternative="scipy.signal.lsim, record by record",
            alternative_s=lsim_seconds * scale,
            alternative_timing=lsim_how,
            target="<= 0.2 s; exact to 1e-6 vs lsim",
            notes=[
                f"largest max abs(z - lsim) / max abs(lsim) per record, {n_lsim} records: "
                f"{els_error.max():.1e}",
                f"lsim: {n_lsim} records per run, scaled x{scale:g}",
                l2("els"),
                load,
            ],
        ),
        Row(
            stage=f"modal r=2, {size}",
            ours_s=ours["modal"][0],
            ours_timing=ours["modal"][1],
            alternative="the same in NumPy from restoring_force",
            alternative_s=generic_seconds,
            alternative_timing=generic_how,
            target="<= 1 s",
            notes=[
                "ours: the structure integrates the projected model (compiled RK4, float32)",
                f"fine-grid nonlinear simulate for context: {fine:.3g} s",
                l2("modal"),
                load,
            ],
        ),
        Row(
            stage=f"relaxed k=30, {size}",
            ours_s=ours["relaxed"][0],
            ours_timing=ours["relaxed"][1],
            alternative="fine-grid nonlinear simulate (context)",
            alternative_s=fine,
            alternative_timing=fine_how,
            target="<= 2 s",
            notes=[
                "3-stage Gauss-Legendre implicit RK at 0.3 s, interpolated to 0.01 s",
                l2("relaxed"),
                load,
            ],
        ),
    ]


def _lsim(system: LinearSystem, motions: cp.GroundMotions) -> np.ndarray:
    """``[n, T, d]`` responses by ``scipy.signal.lsim``, the records one by one."""
    n = system.n_dof
    a = np.block(
        [
            [np.zeros((n, n)), np.eye(n)],
            [
                -np.linalg.solve(system.mass, system.stiffness),
                -np.linalg.solve(system.mass, system.damping),
            ],
        ]
    )
    b = np.concatenate([np.zeros(n), -system.influence])[:, None]
    c = np.hstack([system.output_map, np.zeros_like(system.output_map)])
    model = scipy.signal.StateSpace(a, b, c, np.zeros((c.shape[0], 1)))
    out = [scipy.signal.lsim(model, record, motions.time)[1] for record in motions.acceleration]
    return np.stack(out)


def _generic_modal(building: Structure, motions: cp.GroundMotions):
    """``modal`` (r = 2) through the NumPy path, as a function of no arguments."""
    generic_type = type(
        "WithoutProjectedSimulation",
        (type(building),),
        {
            "simulate_projected": Structure.simulate_projected,
            "capabilities": building.capabilities - {"projected_simulation"},
        },
    )
    modal = cp.create("preprocessor", "modal").fit(generic_type(**building.get_params()))
    return lambda: modal.transform(motions)
