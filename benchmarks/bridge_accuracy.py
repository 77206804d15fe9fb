"""The compiled bridge engine against OpenSees, record by record, across amplitudes.

Every record of Example 2's data is made by the compiled engine; this checks it against
OpenSees' own analysis of the same fibre model on records that span the bridge's range of
response: 20 spectrum-compatible records of the Example 2 scenario (M 7, R_JB 5 km),
scaled so that their peak column drift ratios spread over about 0.1-3 % (scale factors
log-spaced over 0.05-8 of the records as drawn), the first 15 s of each (the strong
motion), dt = 0.01 s. For each record: the relative L2 over the ten outputs (worst output),
the peak error (largest |u_ours - u_OpenSees| over the record, relative to the record's
peak displacement), and whether the two are bit for bit equal. Both engines run one record
at a time in this process.

Run alone with ``python -m benchmarks.bridge_accuracy [--quick]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from cphysfno_opensees.bridge.analysis import analyse
from cphysfno_opensees.bridge.compiled import analyse_compiled, compile_bridge
from cphysfno_opensees.bridge.structure import AuburnRavineBridge
from cphysfno_opensees.loader import import_opensees

import cphysfno_core as cp

from .common import Row, Timing, format_rows, load_average


def run(quick: bool = False) -> list[Row]:
    n_records, n_steps = (3, 301) if quick else (20, 1501)
    bridge = AuburnRavineBridge()
    source = cp.create("ground_motion", "spectrum-compatible", rjb_km=5.0)
    motions = source.sample(n_records, np.random.default_rng(3))
    factors = np.geomspace(0.05, 8.0, n_records)
    compiled = compile_bridge(import_opensees(), bridge.design, bridge.numerics)
    heights = np.repeat(bridge.design.pier_heights, 2)
    load_before = load_average()
    results = []
    ours_total = theirs_total = 0.0
    for factor, record in zip(factors, motions.acceleration, strict=True):
        acceleration = factor * record[:n_steps]
        start = time.process_time()
        ours = analyse_compiled(compiled, bridge.numerics, bridge.damping, acceleration, motions.dt)
        ours_total += time.process_time() - start
        start = time.process_time()
        theirs = analyse(bridge.design, bridge.numerics, bridge.damping, "fibre", None,
                         acceleration, motions.dt)  # fmt: skip
        theirs_total += time.process_time() - start
        # OpenSees applies no ground motion at its last step: compare up to there
        ours, theirs = ours[:-1], theirs[:-1]
        rel_l2 = np.linalg.norm(ours - theirs, axis=0) / np.linalg.norm(theirs, axis=0)
        peak = np.abs(ours - theirs).max() / np.abs(theirs).max()
        drift = (np.abs(theirs).max(axis=0) / heights).max()
        results.append((factor, drift, rel_l2.max(), peak, bool(np.array_equal(ours, theirs))))
    drifts = np.array([r[1] for r in results])
    worst = max(results, key=lambda r: r[2])
    lines = [
        f"factor {f:.3g}: peak column drift {d:.2%}, worst rel. L2 {e:.1e}, peak error {p:.1e}"
        + (" (bit for bit)" if same else "")
        for f, d, e, p, same in results
    ]
    print("\n".join(lines))
    return [
        Row(
            stage=f"compiled bridge engine vs OpenSees, {n_records} records x {n_steps} samples, "
            f"peak column drift {drifts.min():.2%} to {drifts.max():.2%}",
            ours_s=ours_total / n_records,
            ours_timing=Timing(1, False, n_records, "mean per record"),
            alternative="OpenSees' analysis of the same fibre model, same records",
            alternative_s=theirs_total / n_records,
            alternative_timing=Timing(1, False, n_records, "mean per record"),
            target="every record within 1e-3 relative L2 of OpenSees",
            notes=[
                f"worst relative L2 {worst[2]:.1e} (record at factor {worst[0]:.3g}, drift "
                f"{worst[1]:.2%}); worst peak error "
                f"{max(r[3] for r in results):.1e} of the peak displacement",
                f"bit for bit on {sum(r[4] for r in results)} of {n_records} records",
                "CPU s per record, one process, one record at a time",
                f"load average {load_before} before, {load_average()} after",
            ],
        )
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    print(format_rows(run(parser.parse_args().quick)))


if __name__ == "__main__":
    main()
