"""The generic shear building against the dedicated Example 1 kernel.

On 1000 paper white-noise records (3001 samples at 0.01 s): ``shear-building`` with the
Example 1 parameters and a ``bouc-wen`` law given per story (so the generic kernel, with
the law's functions inlined, integrates it, float64, one record per loop, threads over the
cores) against ``bouc-wen-shear-building`` in float64 (the dedicated vectorised kernel,
which ``shear-building`` takes itself when the law is a uniform ``bouc-wen``). Both warm
(compiled before timing), median of 5, all cores. The difference between the two responses
is the accuracy column: they integrate the same equations with the same steps.
"""

from __future__ import annotations

import numpy as np

import cphysfno_core as cp

from .common import Row, load_average, median_time


def run(quick: bool = False) -> list[Row]:
    n_records = 40 if quick else 1000
    motions = cp.create("ground_motion", "white-noise").sample(n_records, np.random.default_rng(0))
    dedicated = cp.create("structure", "bouc-wen-shear-building", precision="float64")
    generic = cp.create(
        "structure",
        "shear-building",
        masses=dedicated.params.masses,
        stiffnesses=dedicated.params.stiffnesses,
        story_law={"name": "bouc-wen", "alpha": (0.1,) * 5},
    )
    load_before = load_average()
    runs = 2 if quick else 5
    ours, ours_how = median_time(lambda: generic.simulate(motions), runs=runs)
    theirs, theirs_how = median_time(lambda: dedicated.simulate(motions), runs=runs)
    a = generic.simulate(motions).displacement
    b = dedicated.simulate(motions).displacement
    error = np.max(np.linalg.norm(a - b, axis=1) / np.linalg.norm(b, axis=1))
    return [
        Row(
            f"shear-building, generic kernel (bouc-wen law per story), {n_records} x 3001",
            ours,
            "the dedicated Example 1 kernel (float64), same records",
            theirs,
            "<= 2x the dedicated kernel",
            [
                f"largest relative L2 between the two: {error:.1e}",
                f"load average {load_before}",
            ],
            ours_timing=ours_how,
            alternative_timing=theirs_how,
        )
    ]
