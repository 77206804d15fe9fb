"""The component registry: one pluggy plugin manager, filled from the ``cphysfno``
entry-point group, indexed by kind and name.

A plugin that fails to import, whose hook raises, or that hands over a malformed
component is recorded as broken (with its error) and does not take the others down.
Two components claiming one name within a kind are both withheld, and asking for that
name says who the two providers are.

Set ``CPHYSFNO_DISABLE_PLUGIN_AUTOLOAD=1`` to skip entry points, and name plugin modules
to load instead in ``CPHYSFNO_PLUGINS`` (comma separated).
"""

from __future__ import annotations

import importlib
import os
from dataclasses import dataclass
from importlib import metadata
from types import ModuleType
from typing import Any

import pluggy

from ..signals.errors import RegistryError
from . import hookspecs
from .interfaces import Params
from .kinds import KIND_NAMES, kind_named

ENTRY_POINT_GROUP = "cphysfno"


@dataclass(frozen=True)
class ComponentEntry:
    """A registered component: its kind, name, class and who provides it."""

    kind: str
    name: str
    cls: type
    plugin: str
    distribution: str

    @property
    def parameters(self) -> dict[str, Any]:
        """Field name -> default (or ``"required"``) of the component's Params model."""
        out = {}
        for field_name, info in self.cls.Params.model_fields.items():
            out[field_name] = "required" if info.is_required() else info.default
        return out


@dataclass(frozen=True)
class BrokenPlugin:
    """A plugin (or one of its components) that could not be used, and why."""

    plugin: str
    distribution: str
    error: str


def plugin_manager() -> pluggy.PluginManager:
    """A plugin manager that knows the cphysfno hook specifications and no plugins."""
    pm = pluggy.PluginManager(hookspecs.PROJECT)
    pm.add_hookspecs(hookspecs.Specifications)
    return pm


def _distribution_label(dist: metadata.Distribution | None) -> str:
    if dist is None:
        return "(unknown distribution)"
    return f"{dist.metadata['Name']} {dist.version}"


class Registry:
    """Components by kind and name, discovered through pluggy.

    Args:
        autoload: load every plugin of the ``cphysfno`` entry-point group.
        plugins: further plugin modules (objects or importable names) to register.
    """

    def __init__(self, autoload: bool = True, plugins: tuple[ModuleType | str, ...] = ()):
        self._pm = plugin_manager()
        self._distribution: dict[str, str] = {}
        self._load_errors: list[BrokenPlugin] = []
        if autoload:
            self._load_entry_points()
        for plugin in plugins:
            self.register(plugin)
        self._index()

    def _load_entry_points(self) -> None:
        for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
            dist = _distribution_label(getattr(ep, "dist", None))
            if self._pm.get_plugin(ep.name) is not None or self._pm.is_blocked(ep.name):
                continue
            try:
                plugin = ep.load()
                self._pm.register(plugin, name=ep.name)
                self._pm.check_pending()
            except Exception as error:  # a broken plugin must not take the others down
                if self._pm.get_plugin(ep.name) is not None:
                    self._pm.unregister(name=ep.name)
                self._load_errors.append(BrokenPlugin(ep.name, dist, _describe(error)))
                continue
            self._distribution[ep.name] = dist

    def register(
        self,
        plugin: ModuleType | object | str,
        name: str | None = None,
        distribution: str = "(registered in code)",
    ) -> None:
        """Register a plugin module or object (or import one by dotted name)."""
        if isinstance(plugin, str):
            name = name or plugin
            try:
                plugin = importlib.import_module(plugin)
            except Exception as error:
                self._load_errors.append(BrokenPlugin(name, distribution, _describe(error)))
                self._index()
                return
        name = self._pm.register(plugin, name=name)
        self._pm.check_pending()
        self._distribution[name] = distribution
        self._index()

    def _index(self) -> None:
        self._entries: dict[tuple[str, str], ComponentEntry] = {}
        self._clashes: dict[tuple[str, str], list[ComponentEntry]] = {}
        self.broken: list[BrokenPlugin] = list(self._load_errors)
        for kind in KIND_NAMES:
            hook = getattr(self._pm.hook, kind_named(kind).hook)
            for impl in hook.get_hookimpls():
                dist = self._distribution.get(impl.plugin_name, "(registered in code)")
                try:
                    classes = list(impl.function() or [])
                except Exception as error:
                    self.broken.append(BrokenPlugin(impl.plugin_name, dist, _describe(error)))
                    continue
                for cls in classes:
                    problem = _malformed(kind, cls)
                    if problem:
                        self.broken.append(BrokenPlugin(impl.plugin_name, dist, problem))
                        continue
                    entry = ComponentEntry(kind, cls.name, cls, impl.plugin_name, dist)
                    self._add(entry)

    def _add(self, entry: ComponentEntry) -> None:
        key = (entry.kind, entry.name)
        if key in self._clashes:
            self._clashes[key].append(entry)
        elif key in self._entries:
            self._clashes[key] = [self._entries.pop(key), entry]
        else:
            self._entries[key] = entry

    def entries(self, kind: str | None = None) -> list[ComponentEntry]:
        """Usable components, sorted by kind then name (all kinds if ``kind`` is None)."""
        found = [e for e in self._entries.values() if kind in (None, e.kind)]
        return sorted(found, key=lambda e: (KIND_NAMES.index(e.kind), e.name))

    def clashes(self) -> dict[tuple[str, str], list[ComponentEntry]]:
        """Names claimed by more than one component of a kind (none of them is usable)."""
        return dict(self._clashes)

    def names(self, kind: str) -> list[str]:
        return [e.name for e in self.entries(kind)]

    def entry(self, kind: str, name: str) -> ComponentEntry:
        """The entry of ``name``; the error lists the known names or says why it is missing."""
        kind_named(kind)
        key = (kind, name)
        if key in self._entries:
            return self._entries[key]
        if key in self._clashes:
            who = " and ".join(
                f"{e.distribution} (plugin '{e.plugin}')" for e in self._clashes[key]
            )
            raise RegistryError(f"{kind} '{name}' is provided by both {who}: uninstall one of them")
        known = ", ".join(self.names(kind)) or "none"
        message = f"unknown {kind} '{name}'; known {kind} names: {known}"
        if self.broken:
            failed = ", ".join(f"'{b.plugin}'" for b in self.broken)
            message += f" (plugins that failed to load: {failed}; see `cphysfno plugins`)"
        raise RegistryError(message)

    def get(self, kind: str, name: str) -> type:
        """The class registered as ``name`` within ``kind``."""
        return self.entry(kind, name).cls

    def create(self, kind: str, name: str, **params: Any) -> Any:
        """Build component ``name`` of ``kind`` from ``params`` validated by its Params model.

        Operators take ``in_channels`` and ``out_channels`` besides their own parameters.
        """
        return self.get(kind, name)(**params)


def _describe(error: BaseException) -> str:
    return f"{type(error).__name__}: {error}"


def _malformed(kind: str, cls: Any) -> str:
    base = kind_named(kind).base
    if not isinstance(cls, type) or not issubclass(cls, base):
        return f"{cls!r} handed over as a {kind} is not a subclass of {base.__name__}"
    if not isinstance(getattr(cls, "name", None), str) or not cls.name:
        return f"{kind} class {cls.__name__} has no registry name (class attribute `name`)"
    if not (isinstance(cls.Params, type) and issubclass(cls.Params, Params)):
        return f"{kind} '{cls.name}': Params must subclass cphysfno_core.plugin.Params"
    return ""


_default: Registry | None = None


def get_registry() -> Registry:
    """The process-wide registry, built on first use (see the module doc for the env vars)."""
    global _default
    if _default is None:
        autoload = os.environ.get("CPHYSFNO_DISABLE_PLUGIN_AUTOLOAD", "") in ("", "0")
        named = os.environ.get("CPHYSFNO_PLUGINS", "")
        plugins = tuple(p.strip() for p in named.split(",") if p.strip())
        _default = Registry(autoload=autoload, plugins=plugins)
    return _default


def set_registry(registry: Registry | None) -> None:
    """Replace the process-wide registry (``None`` rebuilds it on next use)."""
    global _default
    _default = registry


def create(kind: str, name: str, **params: Any) -> Any:
    """Build a registered component by kind and name, e.g. ``create("structure", "x")``."""
    return get_registry().create(kind, name, **params)
