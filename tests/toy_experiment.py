"""The TOML text of small experiments on the components of ``toy_components``."""

from __future__ import annotations

import json


def toy_experiment(
    *,
    n_steps: int,
    data: dict,
    structure: dict | None = None,
    ground_motion: str = "toy-source",
    operator: dict | None = None,
    **sections: dict,
) -> str:
    """The TOML text of an experiment: ``toy-structure`` (``structure`` adds or overrides its
    fields, ``name`` included) shaken by ``n_steps``-step records of ``ground_motion``, the
    ``toy-linear`` preprocessor and ``toy-operator`` (fields in ``operator``), with the data
    splits of ``data`` (``n_train``, ``n_val``, ``n_test``, ``chunk_size``) generated serially.
    Every further keyword (``training``, ``output``, ``study``, ...) is one more section written
    as given; a dict among its values becomes a sub-table (``[study.sweeps.size]``)."""
    experiment = {
        "structure": {"name": "toy-structure", **(structure or {})},
        "ground_motion": {"name": ground_motion, "n_steps": n_steps},
        "preprocessor": [{"name": "toy-linear"}],
        "operator": {"name": "toy-operator", **(operator or {})},
        "data": {**data, "executor": "serial"},
        **sections,
    }
    lines = []
    for name, section in experiment.items():
        if isinstance(section, list):
            for entry in section:
                lines += _table(f"[[{name}]]", entry)
        else:
            lines += _table(f"[{name}]", section)
    return "\n".join(lines) + "\n"


def _table(header: str, fields: dict) -> list[str]:
    """The lines of one table: ``header``, its plain fields, then its dict fields as sub-tables
    named ``header``'s name dot the field's."""
    lines = [header]
    lines += [f"{k} = {json.dumps(v)}" for k, v in fields.items() if not isinstance(v, dict)]
    for key, value in fields.items():
        if isinstance(value, dict):
            lines += _table(f"[{header.strip('[]')}.{key}]", value)
    return lines
