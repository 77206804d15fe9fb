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
