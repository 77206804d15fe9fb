"""The parts of a composite model given by name, ``(name, params)``, spec or instance."""

from __future__ import annotations

from typing import Any

from ..api.registry import get_registry
from ..config.experiment import ComponentSpec
from ..signals.errors import ConfigError

PartLike = str | tuple[str, dict[str, Any]] | ComponentSpec | Any


def as_spec(part: str | tuple | ComponentSpec) -> ComponentSpec:
    """The :class:`ComponentSpec` of a part given by name, ``(name, params)`` or spec."""
    if isinstance(part, ComponentSpec):
        return part
    if isinstance(part, str):
        return ComponentSpec.of(part)
    if isinstance(part, tuple) and len(part) == 2 and isinstance(part[0], str):
        return ComponentSpec.of(part[0], dict(part[1]))
    raise ConfigError(f"a part is a name, a (name, params) pair or an instance, got {part!r}")


def resolve(kind: str, part: PartLike | None) -> Any:
    """An instance of ``kind`` from a name, ``(name, params)``, spec or an instance."""
    if part is None or not isinstance(part, (str, tuple, ComponentSpec)):
        return part
    spec = as_spec(part)
    return get_registry().create(kind, spec.name, **spec.params)


def model_label(
    operator: str,
    preprocessor: str | None = None,
    refined: bool = False,
    residual: bool = False,
) -> str:
    """``fno`` for the baseline, ``c-physfno-els`` for FNO on the ELS response (in general
    ``c-phys<operator>-<preprocessor>``), ``-residual`` behind it for the residual
    formulation, ``refined-`` in front when refined."""
    label = operator if preprocessor is None else f"c-phys{operator}-{preprocessor}"
    label += "-residual" if residual else ""
    return f"refined-{label}" if refined else label
