"""Command line: ``cphysfno plugins | inspect | check | run | generate | train | evaluate |
study | predict | fragility | demands | summarise``."""

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
from ..config.experiment import ExperimentConfig, load_config
from ..config.precision import PRECISIONS
from ..signals.errors import ConfigError, CphysfnoError
from ..signals.progress import QUIET, show_progress
from .study_document import StudySummary


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


def _check(args: argparse.Namespace) -> int:
    from ..data.generation import check_setup

    config = load_config(args.config)
    structure = check_setup(config)
    print(f"{args.config}: the config and its structure check out")
    print(
        f"  structure {structure.name}: {structure.n_outputs} outputs "
        f"({', '.join(structure.output_names)}), T1 = {structure.periods(1)[0]:.3g} s"
    )
    for line in _stories_lines(structure):
        print(f"  {line}")
    names = ", ".join(pp.name for pp in config.preprocessor) or "none"
    print(f"  preprocessors: {names}; {config.data.n_records} records to simulate")
    return 0


def _stories_lines(structure) -> list[str]:
    """What ``cphysfno check`` says of a structure's stories."""
    if "stories" not in structure.capabilities:
        return []
    try:
        stories = structure.stories()
    except ConfigError as error:
        return [f"note: no stories ({error}): no EDPs, and no collapse by drift"]
    heights = ", ".join(f"{h:.3g}" for h in stories.heights_m)
    lines = [f"{stories.n_stories} stories, heights {heights} m"]
    if not stories.has_heights:
        lines.append(
            f"note: {', '.join(stories.without_height())} have no height: drifts in m; "
            "fragility on PID and pelicun demands need story_heights or drift_pairs"
        )
    return lines


def _stage(args: argparse.Namespace) -> int:
    from ..reporting.report import format_table, write_report
    from . import pipeline

    config = _with_models(load_config(args.config), getattr(args, "models", None))
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
    from ..data.layout import STUDY_SUMMARY
    from .study import run_study, summarise_finished, with_seeds
    from .study_report import write_study_report

    config = _with_models(load_config(args.config), args.models)
    if args.seeds is not None:
        config = with_seeds(config, args.seeds)
    out = Path(args.out)
    started = time.perf_counter()
    if args.summary_only:
        summary = summarise_finished(config, out)
        summary.write(out / STUDY_SUMMARY)
    else:
        summary = run_study(config, out, jobs=args.jobs)
    report = write_study_report(config, summary, out)
    _print_means(summary)
    print(f"\nsummary: {out / 'study.json'}\nreport:  {report}")
    show_progress(f"done in {time.perf_counter() - started:.1f} s")
    return 0


def _with_models(config: ExperimentConfig, models: list[str] | None) -> ExperimentConfig:
    """``config`` training only ``models`` (``output.models``); as it is for None."""
    if models is None:
        return config
    return config.model_copy(update={"output": config.output.model_copy(update={"models": models})})


def _summarise(args: argparse.Namespace) -> int:
    from .study import summarise_runs
    from .summary_combination import combine_summaries

    paths = [Path(path) for path in args.runs]
    files = [path for path in paths if path.suffix == ".json"]
    missing = [str(path) for path in files if not path.is_file()]
    if missing:
        raise ConfigError(f"no summary file {', '.join(missing)}")
    folders = [path for path in paths if path.suffix != ".json"]
    parts = [summarise_runs(folders)] if folders else []
    parts += [StudySummary.read(path) for path in files]
    summary = parts[0] if len(parts) == 1 else combine_summaries(parts)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    summary.write(out)
    _print_means(summary)
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
        units=args.units,
        params=args.params,
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


def _fragility(args: argparse.Namespace) -> int:
    from .fragility_study import parse_limit_states, run_fragility

    document = run_fragility(
        Path(args.run),
        limit_states=parse_limit_states(args.limit_states),
        records=args.records,
        motions_file=None if args.motions is None else Path(args.motions),
        model_label=args.model,
        measure=args.im,
        n_bootstrap=args.bootstrap,
        seed=args.seed,
        out=None if args.out is None else Path(args.out),
        config_path=None if args.config is None else Path(args.config),
        non_converged=args.non_converged,
    )
    im = document["intensity_measure"]
    print(
        f"model {document['model']}; {document['test_records']} test records "
        f"({document['collapsed_test_records']} collapsed), {document['large_records']} "
        f"surrogate records in {document['large_seconds']:.0f} s"
    )
    for name, found in document["skipped_records"].items():
        if found["count"]:
            print(f"{found['count']} {name} records could not be predicted: left out of the fits")
    for name, count in document["surrogate_collapses"].items():
        if count:
            print(
                f"{count} {name} records collapse the surrogate's physics: counted as "
                "exceeding every limit state"
            )
    sources = ["simulation", "surrogate", "surrogate-large"]
    modelling = document["modelling_uncertainty"]
    if modelling is not None:
        sources.append("surrogate-large-medians")
        print(
            "modelling uncertainty: the large set draws "
            f"{', '.join(modelling['parameters'])}; surrogate-large-medians sets them at "
            "their medians"
        )
    print(
        f"fragility medians ({im['description']}, {im['unit']}) and beta, "
        f"{' | '.join(sources)} (* flagged):"
    )
    flagged, split = [], []
    for name, fits in document["limit_states"].items():
        cells = []
        found = fits.get("dispersion")
        if found is not None and found["beta_modelling"] is not None:
            split.append(
                f"  {name:<14} total {found['beta_total']:.2f} = record-to-record "
                f"{found['beta_record_to_record']:.2f} (+) modelling "
                f"{found['beta_modelling']:.2f}; median x{found['median_shift']:.2f}"
            )
        for source in sources:
            fit = fits[source]
            if fit["median"] is None:
                cells.append("not reached" if fit["n_exceeded"] == 0 else "every record")
                continue
            mark = "*" if fit["flags"] else ""
            cells.append(f"{fit['median']:.4g}, {fit['beta']:.2f}{mark}")
            flagged += [f"  * {name}, {source}: {flag}" for flag in fit["flags"]]
        print(f"  {name:<14} " + " | ".join(cells))
    if split:
        print("dispersion of the large set, beta (square root of the sum of squares):")
        print("\n".join(split))
    if flagged:
        print("fits the records may not determine:")
        print("\n".join(flagged))
    print(f"\nwritten: {args.out or Path(args.run) / 'fragility'}")
    return 0


def _demands(args: argparse.Namespace) -> int:
    from .demand_sample import write_demand_sample

    written, label = write_demand_sample(
        Path(args.run),
        motions_file=None if args.motions is None else Path(args.motions),
        model_label=args.model,
        out=None if args.out is None else Path(args.out),
        params_file=None if args.params is None else Path(args.params),
        seed=args.seed,
    )
    print(
        f"model {label}: {written.n_records} records ({written.n_collapsed} collapsed, "
        f"flagged in the ERROR column that pelicun drops), {len(written.columns)} demand "
        f"columns\nwritten: {written.path}"
    )
    return 0


def _print_means(summary: StudySummary) -> None:
    """Print the per-output mean relative L2 of every model of a study summary."""
    from ..reporting.report import format_table

    means = {label: {"rel_l2": row.rel_l2.mean} for label, row in summary.models.items()}
    seeds = len(summary.seeds)
    over = f"{seeds} seed" + ("s" if seeds != 1 else "")
    print(f"relative L2 error per output, mean of {over} (test split):")
    print(format_table(means, summary.output_names))


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
    text = (
        "check a config before any work: its fields, its structure's model (nodes, DOFs, "
        "gravity function), its stories and the capabilities its preprocessors need"
    )
    check = commands.add_parser("check", help=text, description=text)
    check.add_argument("config", help="experiment TOML file")
    check.set_defaults(func=_check)
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
        if name != "generate":
            _models_option(stage)
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
        "--seeds",
        type=int,
        nargs="+",
        help="train these training seeds instead of the config's (e.g. a share of the study "
        "on one machine; cphysfno summarise combines the shares' study.json)",
    )
    _models_option(study)
    study.add_argument(
        "--summary-only",
        action="store_true",
        help="summarise the runs finished so far (of a study still running or stopped) "
        "without generating or training",
    )
    study.set_defaults(func=_study)
    text = (
        "predict the displacement histories of ground motions in a file (.npz with "
        "acceleration [N, T], dt in s and units, or .npy with --dt and --units) with a "
        "saved model"
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
        "--units",
        help="unit of the motions of an .npz or .npy file: m/s2, g, cm/s2, mm/s2, in/s2 or "
        "ft/s2 (an .npz may say it in a 'units' entry; AT2 records are in g; without a "
        "unit, m/s2 with a warning)",
    )
    predict.add_argument(
        "--params",
        help="for a model of a family of structures: a CSV file whose header names "
        "structural parameters (their dotted paths, e.g. stiffnesses.0) and whose rows give "
        "their values, one row a record or one row for all; a parameter left out takes the "
        "model's nominal value",
    )
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
    text = (
        "fragility curves of a trained run: fitted from the simulated test records and from "
        "the surrogate's predictions of them and of many new motions, side by side"
    )
    fragility = commands.add_parser("fragility", help=text, description=text)
    fragility.add_argument("run", help="a folder written by cphysfno run")
    fragility.add_argument(
        "--limit-states",
        default="pid=0.005,0.01,0.02",
        help="thresholds, e.g. 'pid=0.005,0.01,0.02;pfa=5;pd:isolator=0.3', demand[:column]"
        "=values with demand an EDP (pid, rid: story drift ratios; pfa, m/s^2; pfv, m/s; pd, "
        "m; pr: a named response's peak in its unit, for a model that learns them) and the "
        "largest over its columns unless one is named; default %(default)s",
    )
    fragility.add_argument(
        "--records", type=int, default=10_000, help="new motions drawn from the run's source"
    )
    fragility.add_argument(
        "--motions", help="read the new motions from a file instead (as predict reads them)"
    )
    fragility.add_argument(
        "--model", help="a model under RUN/models (default: the trained model with the "
        "lowest validation error on the limit states' EDPs)"
    )  # fmt: skip
    fragility.add_argument(
        "--im",
        default="sa-t1",
        help="intensity measure: sa-t1 (5 %% damped, at the structure's T1), sa:T (at T s, "
        "e.g. sa:1.5), sa-avg (geometric mean from 0.2 T1 to 3 T1), sa-avg:A-B (from A to B "
        "s), pga or pgv; default %(default)s",
    )
    fragility.add_argument(
        "--non-converged",
        choices=["exclude", "collapse"],
        default="exclude",
        help="a test record whose analysis stopped converging below the collapse: left out "
        "of the simulation curves (exclude, the default) or counted as a collapse",
    )
    fragility.add_argument(
        "--config",
        help="an edited config file to use instead of the run's saved config.json (its "
        "structure and ground-motion source)",
    )
    fragility.add_argument("--bootstrap", type=int, default=200, help="bootstrap resamples")
    fragility.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seeds the motions, their structural parameters (a family) and the bootstrap",
    )
    fragility.add_argument("--out", help="folder to write to (default RUN/fragility)")
    fragility.set_defaults(func=_fragility)
    text = (
        "the demand sample of a trained run's surrogate (its test records or --motions) in "
        "the CSV that pelicun 3 reads: PID, RID and PFA columns with a units row"
    )
    demands = commands.add_parser("demands", help=text, description=text)
    demands.add_argument("run", help="a folder written by cphysfno run")
    demands.add_argument(
        "--format", choices=["pelicun"], default="pelicun", help="the file format (pelicun)"
    )
    demands.add_argument("--motions", help="predict these motions instead of the test records")
    demands.add_argument("--model", help="a model under RUN/models (default: as fragility)")
    demands.add_argument("--out", help="the CSV to write (default RUN/demands/demands.csv)")
    demands.add_argument(
        "--params",
        help="with --motions, for a model of a family of structures: a CSV of the records' "
        "structural parameters (as cphysfno predict reads it); without it they are drawn "
        "from the config's distributions",
    )
    demands.add_argument(
        "--seed", type=int, default=0, help="seeds the draw of structural parameters"
    )
    demands.set_defaults(func=_demands)
    text = (
        "summarise finished run folders (e.g. one per seed) as study.json does, and combine "
        "them with summaries of other seeds (study.json files, e.g. from another machine)"
    )
    summary = commands.add_parser("summarise", help=text, description=text)
    summary.add_argument(
        "runs",
        nargs="+",
        help="folders written by cphysfno run, and study.json files of disjoint seeds",
    )
    summary.add_argument("--out", required=True, help="JSON file to write")
    summary.set_defaults(func=_summarise)
    return parser


def _models_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--models",
        nargs="+",
        metavar="LABEL",
        help="only these of the config's models, e.g. fno c-physfno-els (output.models: a "
        "share of the work, on one machine; cphysfno summarise combines the shares)",
    )


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
