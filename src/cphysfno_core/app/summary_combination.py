"""Study summaries of disjoint seeds (say, run on two machines) combined into one.

A ``study.json`` keeps per model and output the mean and the standard deviation over its
seeds (``ddof = 0``); with the seed counts these give the sums of the values and of their
squares, so summaries of disjoint seed sets combine to exactly the summary of all the
runs together, without the run folders.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ..signals.errors import ConfigError

_SAME = ("epochs", "sizes", "output_names")
_DEVICES = re.compile(r", (?![^()]*\))")  # the commas between devices, not inside "(...)"


def combine_summaries(summaries: list[dict[str, Any]]) -> dict[str, Any]:
    """One summary of the union of the seeds of ``summaries``.

    Args:
        summaries: ``study.json`` documents (or ``cphysfno summarise`` outputs) of the same
            experiment with disjoint ``seeds``: same epochs, split sizes, outputs and models.

    Returns:
        The schema of ``study.json``: per model and metric the mean and standard deviation
        (``ddof = 0``) over all the seeds, equal to what :func:`summarise` gives on all the
        runs; sweeps' per-seed errors joined; seeds in the order given; the devices of all.

    Raises:
        ConfigError: fewer than two summaries, a seed in two of them, or the summaries
            differ in what they summarise (epochs, sizes, outputs, models, test response
            where both record it).
    """
    if len(summaries) < 2:
        raise ConfigError("combining needs at least two summaries")
    first = summaries[0]
    seeds = [seed for summary in summaries for seed in summary["seeds"]]
    repeated = sorted({seed for seed in seeds if seeds.count(seed) > 1})
    if repeated:
        raise ConfigError(f"seeds {repeated} are in more than one summary")
    recorded = [s["response_rms"] for s in summaries if s.get("response_rms") is not None]
    response = recorded[0] if recorded else None
    for i, summary in enumerate(summaries[1:], start=1):
        for key in _SAME:
            if summary[key] != first[key]:
                raise ConfigError(
                    f"summary {i} has {key} {summary[key]}, summary 0 has {first[key]}"
                )
        if set(summary["models"]) != set(first["models"]):
            different = sorted(set(summary["models"]) ^ set(first["models"]))
            raise ConfigError(f"summary {i} and summary 0 differ in models {different}")
    for i, summary in enumerate(summaries):
        if not _same_response(summary.get("response_rms"), response):
            raise ConfigError(f"summary {i} has another test response than the others")
    counts = [len(summary["seeds"]) for summary in summaries]
    models = {
        label: _combine_model([summary["models"][label] for summary in summaries], counts, label)
        for label in first["models"]
    }
    devices = [part for summary in summaries for part in _DEVICES.split(summary["device"])]
    return {
        "models": models,
        "sweeps": _combine_sweeps([summary["sweeps"] for summary in summaries]),
        "seeds": seeds,
        "epochs": first["epochs"],
        "sizes": first["sizes"],
        "output_names": first["output_names"],
        "response_rms": response,
        "device": ", ".join(dict.fromkeys(devices)),
    }


def _same_response(a: list[float] | None, b: list[float] | None) -> bool:
    """Whether two test responses agree; one that was not recorded (a summary written
    before ``response_rms`` existed) cannot disagree."""
    if a is None or b is None:
        return True
    return bool(np.allclose(a, b, rtol=1e-9, atol=0.0))


def _combine_model(rows: list[dict[str, Any]], counts: list[int], label: str) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in rows[0].items():
        if isinstance(value, dict) and set(value) == {"mean", "std"}:
            out[key] = _pooled([row[key] for row in rows], counts)
        elif any(row.get(key) != value for row in rows):
            raise ConfigError(f"model {label}: {key} differs between the summaries")
        else:
            out[key] = value
    return out


def _pooled(parts: list[dict[str, list[float]]], counts: list[int]) -> dict[str, list[float]]:
    """Mean and ``ddof = 0`` std of the union, from each part's mean, std and count."""
    n = np.asarray(counts, dtype=np.float64)[:, None]
    mean = np.asarray([part["mean"] for part in parts], dtype=np.float64)
    std = np.asarray([part["std"] for part in parts], dtype=np.float64)
    total = (n * mean).sum(axis=0) / n.sum()
    # spread within each part plus the parts' offsets from the total mean
    variance = (n * (std**2 + (mean - total) ** 2)).sum(axis=0) / n.sum()
    return {"mean": total.tolist(), "std": np.sqrt(variance).tolist()}


def _combine_sweeps(sweeps: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for part in sweeps:
        for name, sweep in part.items():
            into = out.setdefault(name, {**sweep, "values": [], "rel_l2": {}})
            if sweep["field"] != into["field"]:
                raise ConfigError(f"sweep {name} sets {sweep['field']} and {into['field']}")
            into["values"] += [v for v in sweep["values"] if v not in into["values"]]
            for label, by_value in sweep["rel_l2"].items():
                for value, rows in by_value.items():
                    into["rel_l2"].setdefault(label, {}).setdefault(value, []).extend(rows)
    return out
