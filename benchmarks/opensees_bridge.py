"""Data generation speed for the Auburn Ravine type bridge of Example 2.

Ours is ``AuburnRavineBridge.simulate`` with its default numerics on spectrum-compatible
records of the bridge scenario (M 7, R_JB 5 km, 3001 samples at 0.01 s), two worker
processes, timed on a subset and scaled linearly to 1000 records. The alternative is the
same model in its reference configuration (a fine fibre mesh, 48 sectors x 12 core rings x
4 cover rings, and a Newton tolerance of 1e-10 m), which the defaults must reproduce within
1e-3 relative L2 per pier. The ``els`` row is the linear representation solved exactly
for all 1000 records.
"""

from __future__ import annotations

import time

import numpy as np

import cphysfno_core as cp
from cphysfno_core import metrics

from .common import Row, load_average

REFERENCE = {"sectors": 48, "core_rings": 12, "cover_rings": 4, "tolerance": 1e-10}


def run(quick: bool = False) -> list[Row]:
    n_records, n_timed = (1000, 2) if quick else (1000, 10)
    steps = 301 if quick else None
    source = cp.create("ground_motion", "spectrum-compatible", rjb_km=5.0)
    motions = source.sample(n_timed, np.random.default_rng(0))
    if steps is not None:
        motions = cp.GroundMotions(motions.acceleration[:, :steps], motions.dt)
    ours = cp.create("structure", "auburn-ravine-bridge", workers=2)
    reference = cp.create("structure", "auburn-ravine-bridge", workers=2, **REFERENCE)
    load_before = load_average()
    ours_s, u = _timed(ours, motions)
    reference_s, truth = _timed(reference, motions)
    error = metrics.relative_l2(u, truth)
    els = cp.create("preprocessor", "els").fit(ours)
    all_records = cp.GroundMotions(
        np.tile(motions.acceleration, (n_records // n_timed, 1)), motions.dt
    )
    start = time.perf_counter()
    z = els.transform(all_records)
    els_s = time.perf_counter() - start
    scale = n_records / n_timed
    size = f"{n_records} x {motions.n_steps} x 10"
    load = f"load average {load_before} before, {load_average()} after"
    return [
        Row(
            stage=f"Auburn Ravine bridge truth, {size}, 2 workers",
            ours_s=ours_s * scale,
            alternative="the reference configuration (fibres 48 x 12 x 4, tolerance 1e-10 m)",
            alternative_s=reference_s * scale,
            target="<= 1200 s (2.4 s per record per core)",
            notes=[
                f"{n_timed} records timed, scaled x{scale:g}",
                f"ours: {ours_s / n_timed * 2:.2f} s per record per core, reference "
                f"{reference_s / n_timed * 2:.2f}",
                f"relative L2 to the reference per pier, largest {error.max():.1e} (limit 1e-3)",
                load,
            ],
        ),
        Row(
            stage=f"Auburn Ravine bridge els, {size}",
            ours_s=els_s,
            target="exact linear response of the 103-DOF condensed system",
            notes=[f"finite: {bool(np.isfinite(z).all())}", load],
        ),
    ]


def _timed(structure, motions) -> tuple[float, np.ndarray]:
    """Wall time in s of simulating ``motions``, and the displacements."""
    start = time.perf_counter()
    u = structure.simulate(motions).displacement
    return time.perf_counter() - start, u
