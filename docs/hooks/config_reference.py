"""MkDocs hook: write ``reference/config.md`` from the pydantic models of the config and
of every registered component, so the reference cannot drift from the code."""

from __future__ import annotations

from typing import Any

from mkdocs.structure.files import File

from cphysfno_core.api import KINDS
from cphysfno_core.api.registry import get_registry
from cphysfno_core.config import experiment as config_module

SECTIONS = [
    ("[data]", config_module.DataConfig),
    ("[training]", config_module.TrainingConfig),
    ("[formulation]", config_module.FormulationConfig),
    ("[output]", config_module.OutputConfig),
    ("[study]", config_module.StudyConfig),
    ("[study.sweeps.<name>]", config_module.SweepConfig),
]


def _default(info: Any) -> str:
    return "required" if info.is_required() else f"`{info.default!r}`"


def _table(model: type) -> list[str]:
    lines = ["| field | default | meaning |", "|---|---|---|"]
    for name, info in model.model_fields.items():
        text = (info.description or "").replace("|", "\\|")
        lines.append(f"| `{name}` | {_default(info)} | {text} |")
    return lines


def render() -> str:
    """The configuration reference as Markdown."""
    lines = [
        "# Configuration reference",
        "",
        "An experiment is one TOML file. Component sections (`[structure]`,",
        "`[ground_motion]`, `[[preprocessor]]`, `[operator]`, `[refiner]`) hold",
        '`name = "..."` and that component\'s own fields, listed below for every installed',
        "component. Unknown fields are errors that name their path.",
        "",
    ]
    for title, model in SECTIONS:
        lines += [f"## {title}", "", (model.__doc__ or "").strip(), "", *_table(model), ""]
    registry = get_registry()
    for kind in (k.name for k in KINDS):
        lines += [f"## [{kind}] components", ""]
        for entry in registry.entries(kind):
            summary = (entry.cls.__doc__ or "").strip().splitlines()[0]
            lines += [f"### `{entry.name}`", "", f"{summary} ({entry.distribution})", ""]
            lines += _table(entry.cls.Params) + [""]
    return "\n".join(lines)


def on_files(files, config):
    """Add the generated page to the site."""
    files.append(File.generated(config, "reference/config.md", content=render()))
    return files
