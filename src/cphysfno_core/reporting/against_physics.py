"""Each C-Phys model against its own physics input z, and the choice between the paper's
and the residual formulation, from the rows of ``metrics.json``.

A row of a C-Phys model holds ``physics_input`` (the label of its ``physics-*`` row),
``rel_l2`` (test) and ``validation_rel_l2``, each ``[dof]``; a ``physics-*`` row holds the
same two errors of z alone.
"""

from __future__ import annotations

from ..model.labels import ModelLabel

SPLITS = {"validation": "validation_rel_l2", "test": "rel_l2"}
"""Split name -> key of its relative L2 in a metrics row."""


def shortfalls(models: dict[str, dict], output_names: list[str]) -> dict[str, dict[str, list]]:
    """Where a C-Phys model ends worse than its physics input.

    Returns:
        label -> split (``"validation"``, ``"test"``) -> ``[(output, model error, physics
        error), ...]`` for every output whose relative L2 exceeds that of z alone; models
        and splits with none are left out.
    """
    found: dict[str, dict[str, list]] = {}
    for label, row in models.items():
        physics = models.get(row.get("physics_input", ""))
        if physics is None:
            continue
        for split, key in SPLITS.items():
            worse = [
                (name, ours, theirs)
                for name, ours, theirs in zip(output_names, row[key], physics[key], strict=True)
                if ours > theirs
            ]
            if worse:
                found.setdefault(label, {})[split] = worse
    return found


def describe_shortfalls(found: dict[str, dict[str, list]]) -> list[str]:
    """One sentence per model of :func:`shortfalls`, with the errors side by side."""
    lines = []
    for label, splits in found.items():
        parts = [
            f"on {split} at "
            + ", ".join(f"{name} ({ours:.3f} against {theirs:.3f})" for name, ours, theirs in worse)
            for split, worse in splits.items()
        ]
        advice = (
            "z alone is the better answer there"
            if ModelLabel.parse(label).residual
            else "train it in the residual form ([formulation] residual = true, or 'choose' "
            "to train both and compare), or use z"
        )
        lines.append(
            f"{label} is worse than its physics input z alone " + "; ".join(parts) + ": " + advice
        )
    return lines


def chosen_forms(models: dict[str, dict]) -> dict[str, str]:
    """For every model trained in both forms, the form with the lower mean validation
    relative L2: paper-form label -> the chosen label (itself or its ``-residual`` twin)."""
    chosen = {}
    for label, row in models.items():
        parsed = ModelLabel.parse(label)
        if parsed.is_physics or parsed.residual:
            continue
        twin_label = str(parsed.residual_twin)
        twin = models.get(twin_label)
        if twin is None or "validation_rel_l2" not in row:
            continue
        paper_error = sum(row["validation_rel_l2"]) / len(row["validation_rel_l2"])
        residual_error = sum(twin["validation_rel_l2"]) / len(twin["validation_rel_l2"])
        chosen[label] = twin_label if residual_error < paper_error else label
    return chosen
