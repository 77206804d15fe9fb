"""Run every benchmark and print the table: ``python -m benchmarks [name ...]``."""

from __future__ import annotations

import argparse
import datetime
import importlib
import sys

from cphysfno_core.allocator import retain_freed_memory

from .common import format_rows, machine

MODULES = (
    "bouc_wen",
    "physics",
    "spectrum_matching",
    "training",
    "prediction",
    "memory",
    "opensees_bridge",
    "opensees_frame",
)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    parser.add_argument("names", nargs="*", help=f"some of {', '.join(MODULES)} (default: all)")
    parser.add_argument("--quick", action="store_true", help="small sizes, for a smoke test")
    args = parser.parse_args(argv)
    unknown = sorted(set(args.names) - set(MODULES))
    if unknown:
        parser.error(f"unknown benchmark {', '.join(unknown)}: choose from {', '.join(MODULES)}")
    retain_freed_memory()
    rows = []
    for name in args.names or MODULES:
        module = importlib.import_module(f"benchmarks.{name}")
        print(f"running {name} ...", file=sys.stderr, flush=True)
        rows += module.run(quick=args.quick)
    print(f"{datetime.date.today().isoformat()} on {machine()}\n")
    print(format_rows(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
