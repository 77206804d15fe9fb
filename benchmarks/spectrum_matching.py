"""Spectrum-compatible records: how many match their own target, and how fast.

200 records of the default scenario (``sample(200, default_rng(2024))``): the share within
10 % and 20 % of the record's own target at every matching period, the geometric mean and
log-standard deviation of the matched spectra against the drawn targets', and the final
ground velocity and displacement. No alternative is timed: the number is records per second.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

import cphysfno_core as cp
from cphysfno_core.signals.intensity import response_spectrum, velocity_displacement

from .common import Row, load_average


def run(quick: bool = False) -> list[Row]:
    n_records = 20 if quick else 200
    source = cp.create("ground_motion", "spectrum-compatible")
    before = load_average()
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        motions = source.sample(n_records, np.random.default_rng(2024))
    seconds = time.perf_counter() - start
    periods = source.matching_periods
    psa = response_spectrum(motions.acceleration, motions.dt, periods).pseudo_acceleration
    target = np.array([record["target_psa"] for record in motions.metadata])
    misfit = np.expm1(np.abs(np.log(psa / target)).max(axis=1))
    log_psa, log_target = np.log(psa), np.log(target)
    median = np.abs(np.expm1(log_psa.mean(0) - log_target.mean(0))).max()
    spread = np.abs(log_psa.std(0) / log_target.std(0) - 1.0).max()
    velocity, displacement = velocity_displacement(motions.acceleration, motions.dt)
    retried = sum(record["match_attempts"] > 1 for record in motions.metadata)
    return [
        Row(
            stage=f"spectrum-compatible, {n_records} records x {motions.n_steps}",
            ours_s=seconds,
            target="each record within 10 % of its own target over 0.1-5 s",
            notes=[
                f"{n_records / seconds:.1f} records/s",
                f"within 10 %: {(misfit <= 0.1).mean():.1%}, within 20 %: "
                f"{(misfit <= 0.2).mean():.1%}, worst {misfit.max():.3f}; {retried} retried",
                f"geometric mean of the spectra within {median:.1%} of the targets', "
                f"log-std within {spread:.1%}, at every period",
                f"final |v| <= {np.abs(velocity[:, -1]).max():.1e} m/s, final |d| <= "
                f"{np.abs(displacement[:, -1]).max():.1e} m",
                f"load average {before} before, {load_average()} after",
            ],
        )
    ]
