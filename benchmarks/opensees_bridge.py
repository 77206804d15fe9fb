"""Data generation speed for the Auburn Ravine type bridge of Example 2.

Ours is ``AuburnRavineBridge.simulate`` with its defaults (the compiled engine) on
spectrum-compatible records of the bridge scenario (M 7, R_JB 5 km, 3001 samples at
0.01 s), two worker processes, timed on a subset and scaled linearly to 1000 records;
beside it the same model run by OpenSees itself (``engine = "opensees"``), one record
after another in two processes, which is what a user of OpenSeesPy would otherwise run.
Accuracy is measured against OpenSees on the same records (the engine's error) and
against the reference configuration (a fine fibre mesh, 48 sectors x 12 core rings x 4
cover rings, a Newton tolerance of 1e-10 m and OpenSees' iterative element state
determination, solved by the compiled engine): the default mesh's error, which the plugin
README sets beside finer meshes and the time step. The ``relaxed`` row is the preprocessor of
``examples/bridge.toml`` (the bridge on the 0.1 s grid) on the same records, the other
part of a data set's nonlinear analyses; the ``els`` row is the linear representation
solved exactly for all 1000 records.
"""

from __future__ import annotations

import time

import numpy as np

import cphysfno_core as cp
from cphysfno_core.reporting import metrics

from .common import Row, load_average

REFERENCE = {
    "sectors": 48,
    "core_rings": 12,
    "cover_rings": 4,
    "tolerance": 1e-10,
    "iterative_elements": True,
}


def run(quick: bool = False) -> list[Row]:
    n_records, n_timed = (1000, 2) if quick else (1000, 10)
    steps = 301 if quick else None
    source = cp.create("ground_motion", "spectrum-compatible", rjb_km=5.0)
    motions = source.sample(n_timed, np.random.default_rng(0))
    if steps is not None:
        motions = cp.GroundMotions(motions.acceleration[:, :steps], motions.dt)
    ours = cp.create("structure", "auburn-ravine-bridge", workers=2)
    opensees = cp.create("structure", "auburn-ravine-bridge", workers=2, engine="opensees")
    reference = cp.create("structure", "auburn-ravine-bridge", workers=2, **REFERENCE)
    load_before = load_average()
    ours_s, u = _timed(ours, motions)
    opensees_s, u_opensees = _timed(opensees, motions)
    _, truth = _timed(reference, motions)
    relaxed = cp.create("preprocessor", "relaxed", factor=10).fit(ours)
    start = time.perf_counter()
    relaxed.transform(motions)
    relaxed_s = time.perf_counter() - start
    els = cp.create("preprocessor", "els").fit(ours)
    all_records = cp.GroundMotions(
        np.tile(motions.acceleration, (n_records // n_timed, 1)), motions.dt
    )
    start = time.perf_counter()
    z = els.transform(all_records)
    els_s = time.perf_counter() - start
    # OpenSees applies no ground motion at the last step (see the plugin README)
    error = metrics.relative_l2(u[:, :-1], truth[:, :-1])
    engines = metrics.relative_l2(u[:, :-1], u_opensees[:, :-1])
    scale = n_records / n_timed
    size = f"{n_records} x {motions.n_steps} x 10"
    load = f"load average {load_before} before, {load_average()} after"
    per_core = 2.0 / n_timed
    return [
        Row(
            stage=f"Auburn Ravine bridge truth, {size}, 2 workers",
            ours_s=ours_s * scale,
            alternative="the same model in OpenSees (engine = opensees), 2 processes",
            alternative_s=opensees_s * scale,
            target="set of 1000 (with relaxed) <= 1200 s",
            notes=[
                f"{n_timed} records timed, scaled x{scale:g}",
                f"ours: {ours_s * per_core:.2f} s per record per core, OpenSees "
                f"{opensees_s * per_core:.2f}",
                f"relative L2 per pier, largest: to OpenSees {engines.max():.1e}, to the "
                f"reference {error.max():.1e} (the default mesh's error)",
                load,
            ],
        ),
        Row(
            stage=f"Auburn Ravine bridge relaxed (k = 10), {size}, 2 workers",
            ours_s=relaxed_s * scale,
            target="with the truth: <= 1200 s",
            notes=[
                f"{relaxed_s * per_core:.2f} s per record per core",
                f"truth + relaxed: {(ours_s + relaxed_s) * scale:.0f} s for the set",
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
