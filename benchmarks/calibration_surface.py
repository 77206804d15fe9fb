"""The stick of each member of a family: fitted to the member (a pushover each) against made
from the calibration surface (``[uncertainty] physics = "surface"``: fitted at 2 k + 1
members only), on a family config (default: examples/opensees-model-imk-family.toml).

``python -m benchmarks.calibration_surface [--config FILE] [--records N]``: the members are
the family's structure with each random parameter at the standard normal numbers ``-2.5,
-1.5, -0.5, 0.5, 1.5, 2.5`` of its distribution (all parameters together), so that the
outer two lie beyond the surface's outer members (at ±2). On ``N`` records of the config's
own ground-motion source (seed 1), per member: the relative L2 of z (pooled over records,
samples and outputs) of the surface's stick against the member's own stick, and of each
stick and of the ELS of the initial stiffness against the member's simulation; the
seconds to fit the surface and to fit one member's stick (one process, warm).
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

import cphysfno_core as cp
from cphysfno_core import CphysfnoWarning
from cphysfno_core.config.calibration_surface import fit_surface
from cphysfno_core.config.uncertainty import with_values
from cphysfno_core.reporting.metrics import relative_l2

from .common import load_average, machine

EXAMPLES = Path(__file__).parents[1] / "examples"
MEMBERS_Z = (-2.5, -1.5, -0.5, 0.5, 1.5, 2.5)
SEED = 1


def pooled(z: np.ndarray, truth: np.ndarray) -> float:
    """Relative L2 over every record, sample and output."""
    return float(relative_l2(z.reshape(1, -1, 1), truth.reshape(1, -1, 1))[0])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.calibration_surface")
    parser.add_argument("--config", type=Path, default=EXAMPLES / "opensees-model-imk-family.toml")
    parser.add_argument("--records", type=int, default=4)
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", CphysfnoWarning)
    config = cp.load_config(args.config)
    space = config.uncertain_parameters()
    spec = config.structure
    nominal = cp.create("structure", spec.name, **spec.params)
    source = cp.create("ground_motion", config.ground_motion.name, **config.ground_motion.params)
    motions = source.sample(args.records, np.random.default_rng(SEED))
    print(f"{machine()}; load average {load_average()}")
    started = time.perf_counter()
    surface = fit_surface(
        {"name": "stick"}, nominal, space.names, space.values_at(-2.0), space.values_at(2.0), print
    )
    surface_seconds = time.perf_counter() - started
    like = {k: v for k, v in surface.preprocessor.items() if k != "name"}
    print(
        f"surface: {surface_seconds:.1f} s for {2 * len(space.names) + 1} fits; law {like['laws']}"
    )
    print("| z | " + " | ".join(space.names) + " | surface vs own stick | own stick vs truth "
          "| surface stick vs truth | ELS vs truth | own stick fit (s) |")  # fmt: skip
    print("|---" * (len(space.names) + 6) + "|")
    for z in MEMBERS_Z:
        values = dict(zip(space.names, space.values_at(z).tolist(), strict=True))
        member = cp.create("structure", spec.name, **with_values(spec.params, values))
        started = time.perf_counter()
        own = cp.create("preprocessor", "stick", **like).fit(member)
        fit_seconds = time.perf_counter() - started
        own_z = own.transform(motions)
        fast_z = surface.preprocessor_at(member, values).transform(motions)
        els_z = cp.create("preprocessor", "els").fit(member).transform(motions)
        truth = member.simulate(motions).displacement
        cells = [f"{v:.4g}" for v in values.values()]
        cells += [f"{pooled(fast_z, own_z):.3f}", f"{pooled(own_z, truth):.3f}"]
        cells += [
            f"{pooled(fast_z, truth):.3f}",
            f"{pooled(els_z, truth):.3f}",
            f"{fit_seconds:.1f}",
        ]
        print(f"| {z:+.1f} | " + " | ".join(cells) + " |", flush=True)
    print(f"load average after: {load_average()}")


if __name__ == "__main__":
    main()
