"""Run every benchmark and print the table: ``python -m benchmarks [name ...]``
(``--device cuda training prediction`` for the GPU rows)."""

from __future__ import annotations

import argparse
import datetime
import importlib
import sys

from cphysfno_core import CphysfnoError
from cphysfno_core.config.allocator import tune_memory
from cphysfno_core.model.training import resolve_device

from .common import format_rows, machine

MODULES = (
    "bouc_wen",
    "physics",
    "spectrum_matching",
    "training",
    "prediction",
    "bfloat16",
    "memory",
    "opensees_bridge",
    "opensees_frame",
    "shear_building",
    "bridge_accuracy",
    "fragility",
)
ON_DEVICE = ("training", "prediction")
"""The benchmarks that run on ``--device``; the others are CPU work."""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    parser.add_argument("names", nargs="*", help=f"some of {', '.join(MODULES)} (default: all)")
    parser.add_argument("--quick", action="store_true", help="small sizes, for a smoke test")
    parser.add_argument(
        "--device",
        default="cpu",
        help=f"torch device for {' and '.join(ON_DEVICE)} (default cpu; e.g. cuda)",
    )
    args = parser.parse_args(argv)
    unknown = sorted(set(args.names) - set(MODULES))
    if unknown:
        parser.error(f"unknown benchmark {', '.join(unknown)}: choose from {', '.join(MODULES)}")
    names = args.names or MODULES
    if args.device != "cpu":
        if set(names) - set(ON_DEVICE):
            parser.error(f"--device {args.device}: name only {' and '.join(ON_DEVICE)}")
        try:
            resolve_device(args.device)
        except CphysfnoError as error:
            parser.error(str(error))
    tune_memory()
    rows = []
    for name in names:
        module = importlib.import_module(f"benchmarks.{name}")
        print(f"running {name} ...", file=sys.stderr, flush=True)
        on_device = {"device": args.device} if name in ON_DEVICE else {}
        rows += module.run(quick=args.quick, **on_device)
    print(f"{datetime.date.today().isoformat()} on {machine()}\n")
    print(format_rows(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
