"""Command line: ``cphysfno plugins | run | generate | train | evaluate``."""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import time
from collections.abc import Callable
from importlib import metadata
from pathlib import Path

from ..api.registry import Registry, get_registry
from ..config.allocator import tune_memory
from ..config.experiment import load_config
from ..config.precision import PRECISIONS
from ..signals.errors import CphysfnoError
from ..signals.progress import QUIET, show_progress


def components_markdown(registry: Registry) -> str:
    """A Markdown table of the usable components: kind, name, distribution and the first
    paragraph of the class's docstring (the README's components table)."""
    lines = ["| kind | name | distribution | what |", "|---|---|---|---|"]
    for e in registry.entries():
        paragraph = (e.cls.__doc__ or "").strip().split("\n\n")[0]
        what = " ".join(paragraph.split()).replace("``", "`")
        distribution = e.distribution.split(" ")[0]
        lines.append(f"| {e.kind} | `{e.name}` | `{distribution}` | {what} |")
    return "\n".join(lines)


def _inspect(args: argparse.Namespace) -> int:
    from .inspection import describe_file

    print(describe_file(args.file, records=args.records))
    return 0


def _plugins(args: argparse.Namespace) -> int:
    registry = get_registry()
    by_kind: dict[str, list] = {}
    for entry in registry.entries():
        by_kind.setdefault(entry.kind, []).append(entry)
    if args.json:
        document = {
            "components": [
                {
                    "kind": e.kind,
                    "name": e.name,
                    "distribution": e.distribution,
                    "plugin": e.plugin,
                    "parameters": e.parameters,
                }
                for e in registry.entries()
            ],
            "broken": [vars(b) for b in registry.broken],
            "clashes": [
                {"kind": k, "name": n, "providers": [e.distribution for e in entries]}
                for (k, n), entries in registry.clashes().items()
            ],
        }
        print(json.dumps(document, indent=2, default=str))
        return 0
    if args.markdown:
        print(components_markdown(registry))
        return 0
    for kind, entries in by_kind.items():
        print(f"{kind}:")
        for e in entries:
            print(f"  {e.name:<28} {e.distribution}")
            params = ", ".join(f"{k}={v!r}" for k, v in e.parameters.items())
            print(f"  {'':<28} parameters: {params or '(none)'}")
    for (kind, name), entries in registry.clashes().items():
        providers = " and ".join(e.distribution for e in entries)
        print(f"clash: {kind} '{name}' is provided by {providers} (neither is usable)")
    if registry.broken:
        print("broken:")
        for b in registry.broken:
            print(f"  {b.plugin:<28} {b.distribution}: {b.error}")
    return 0


def _stage(args: argparse.Namespace) -> int:
    from ..reporting.report import format_table, write_report
    from . import pipeline

    config = load_config(args.config)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    if args.command == "run":
        evaluation = pipeline.run(config, out, resume=args.resume)
    elif args.command == "generate":
        pipeline.generate(config, out)
        evaluation = None
    elif args.command == "train":
        pipeline.train(config, out, resume=args.resume)
        evaluation = None
    else:
        evaluation = pipeline.evaluate(config, out)
        write_report(config, evaluation, out)
    if evaluation is not None:
        names = list(evaluation.data.output_names)
        print("relative L2 error per output (test split):")
        print(format_table(evaluation.metrics, names))
        print(f"\nmetrics: {out / 'metrics.json'}\nreport:  {out / 'report.md'}")
    show_progress(f"done in {time.perf_counter() - started:.1f} s")
    return 0


def _study(args: argparse.Namespace) -> int:
    from .study import SUMMARY, run_study, summarise_finished
    from .study_report import write_study_report

    config = load_config(args.config)
    out = Path(args.out)
    started = time.perf_counter()
    if args.summary_only:
        summary = summarise_finished(config, out)
        (out / SUMMARY).write_text(json.dumps(summary, indent=2))
    else:
        summary = run_study(config, out, jobs=args.jobs)
    report = write_study_report(config, summary, out)
    seeds = len(summary["seeds"])
    _print_means(summary, f"{seeds} seed" + ("s" if seeds != 1 else ""))
    print(f"\nsummary: {out / 'study.json'}\nreport:  {report}")
    show_progress(f"done in {time.perf_counter() - started:.1f} s")
    return 0


def _summarise(args: argparse.Namespace) -> int:
    from .study import summarise_runs

    summary = summarise_runs([Path(folder) for folder in args.runs])
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(summary, indent=2))
    _print_means(summary, f"{len(args.runs)} runs")
    print(f"\nsummary: {out}")
    return 0


def _predict(args: argparse.Namespace) -> int:
    from ..model.prediction_files import predict_file

    run = predict_file(
        args.model,
        args.motions,
        args.out,
        dt=args.dt,
        on_grid=args.on_grid,
        device=args.device,
        precision=args.precision,
    )
    print(
        f"{run.records} records predicted in {run.seconds:.2f} s "
        f"({1e3 * run.seconds / run.records:.1f} ms per record)"
    )
    print("peak |displacement| per output, median over records (m):")
    for name, peak in run.peaks.items():
        print(f"  {name:<12} {peak:.4g}")
    print(f"\npredictions: {run.out}")
    return 0


def _print_means(summary: dict, over: str) -> None:
    """Print the per-output mean relative L2 of every model of a study summary."""
    from ..reporting.report import format_table

    means = {label: {"rel_l2": row["rel_l2"]["mean"]} for label, row in summary["models"].items()}
    print(f"relative L2 error per output, mean of {over} (test split):")
    print(format_table(means, summary["output_names"]))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cphysfno",
        description="Composite physics-neural operators for seismic response prediction.",
    )
    parser.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=0,
        help="also show the library's and the plugins' log messages (-vv: debugging detail)",
    )
    parser.add_argument(
        "-q", "--quiet", action="store_true", help="show only errors: no progress lines"
    )
    parser.add_argument(
        "--version", action="version", version=f"cphysfno {metadata.version('cphysfno-core')}"
    )
    commands = parser.add_subparsers(dest="command", required=True)
    plugins = commands.add_parser("plugins", help="list registered components by kind")
    plugins.add_argument("--json", action="store_true", help="machine-readable output")
    plugins.add_argument(
        "--markdown", action="store_true", help="a Markdown table, as in the README"
    )
    plugins.set_defaults(func=_plugins)
    inspect = commands.add_parser(
        "inspect", help="what a dataset.h5 or prediction .npz holds: arrays, units, records"
    )
    inspect.add_argument("file", help="a dataset.h5 or a prediction .npz")
    inspect.add_argument(
        "--records", type=int, default=5, help="records whose provenance is shown (default 5)"
    )
    inspect.set_defaults(func=_inspect)
    stages = {
        "run": "generate data, train every model, evaluate and write the report",
        "generate": "simulate the dataset (resumes an interrupted run)",
        "train": "train the models on the generated dataset",
        "evaluate": "evaluate the trained models and write metrics.json and report.md",
    }
    for name, text in stages.items():
        stage = commands.add_parser(name, help=text, description=text)
        stage.add_argument("config", help="experiment TOML file")
        stage.add_argument("--out", required=True, help="output folder")
        if name in ("run", "train"):
            stage.add_argument(
                "--resume",
                action="store_true",
                help="keep trained models and continue an interrupted one from its checkpoint",
            )
        stage.set_defaults(func=_stage)
    text = (
        "run the [study] of a config: every seed and sweep, resuming where it stopped; "
        "writes study.json and study.md"
    )
    study = commands.add_parser("study", help=text, description=text)
    study.add_argument("config", help="experiment TOML file with a [study] section")
    study.add_argument("--out", required=True, help="output folder")
    study.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="runs trained at a time, each in its own process (default 1)",
    )
    study.add_argument(
        "--summary-only",
        action="store_true",
        help="summarise the runs finished so far (of a study still running or stopped) "
        "without generating or training",
    )
    study.set_defaults(func=_study)
    text = (
        "predict the displacement histories of ground motions in a file (.npz with "
        "acceleration [N, T] in m/s^2 and dt in s, or .npy with --dt) with a saved model"
    )
    predict = commands.add_parser("predict", help=text, description=text)
    predict.add_argument("model", help="a saved model's folder, e.g. runs/x/models/<label>")
    predict.add_argument(
        "motions",
        help="a PEER .AT2 file or a folder of them, an .npz (acceleration, dt) or an .npy "
        "file (with --dt)",
    )
    predict.add_argument("--out", required=True, help=".npz file to write")
    predict.add_argument("--dt", type=float, help="time step of a .npy file, s")
    predict.add_argument(
        "--on-grid",
        action="store_true",
        help="resample records on another time grid to the model's (anti-aliased, then cut "
        "or zero-padded at the end) instead of refusing them",
    )
    predict.add_argument(
        "--device", default="auto", help="where the operator runs (auto, cpu, cuda, ...)"
    )
    predict.add_argument(
        "--precision",
        choices=PRECISIONS,
        default="float32",
        help="the operator's arithmetic: float32 as trained (default) or bfloat16 products, "
        "about twice as fast on a CPU with native bfloat16, moving predictions by about 0.2 %%",
    )
    predict.set_defaults(func=_predict)
    text = "summarise finished run folders (e.g. one per seed) as study.json does"
    summary = commands.add_parser("summarise", help=text, description=text)
    summary.add_argument("runs", nargs="+", help="folders written by cphysfno run")
    summary.add_argument("--out", required=True, help="JSON file to write")
    summary.set_defaults(func=_summarise)
    return parser


def configure_output(verbose: int, quiet: bool) -> Callable[[], None]:
    """Where the library's messages go: progress lines unless ``quiet`` (also in the worker
    processes, through ``CPHYSFNO_QUIET``); log records of the package and its plugins
    (e.g. the OpenSees plugin's per-record progress) at WARNING, INFO with ``-v``, DEBUG
    with ``-vv``, ERROR only with ``-q``.

    Returns:
        A function that puts everything back as it was.
    """
    before = os.environ.get(QUIET)
    if quiet:
        os.environ[QUIET] = "1"
    levels = [logging.WARNING, logging.INFO, logging.DEBUG]
    level = logging.ERROR if quiet else levels[min(verbose, 2)]
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(name)s: %(message)s"))
    handler.addFilter(lambda record: record.name.startswith("cphysfno"))
    root = logging.getLogger()
    root_level = root.level
    root.addHandler(handler)
    root.setLevel(level)

    def restore() -> None:
        root.removeHandler(handler)
        root.setLevel(root_level)
        if before is None:
            os.environ.pop(QUIET, None)
        else:
            os.environ[QUIET] = before

    return restore


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    restore = configure_output(args.verbose, args.quiet)
    tune_memory()
    try:
        return args.func(args)
    except CphysfnoError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            "interrupted: run the same command again to resume (add --resume to run or "
            "train to continue training from the last epoch)",
            file=sys.stderr,
        )
        return 130
    finally:
        restore()


if __name__ == "__main__":
    sys.exit(main())
