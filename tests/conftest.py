import os
import sys
from pathlib import Path

import pytest

import cphysfno_core as cp
from cphysfno_core.registry import set_registry

sys.path.insert(0, str(Path(__file__).parent))

import toy_components  # noqa: E402


@pytest.fixture
def toy_registry():
    """The process registry replaced by one holding only the toy components."""
    registry = cp.Registry(autoload=False, plugins=(toy_components,))
    set_registry(registry)
    yield registry
    set_registry(None)


@pytest.fixture
def toys_in_workers(toy_registry, monkeypatch):
    """Worker processes load the toy components instead of the installed plugins."""
    monkeypatch.setenv("CPHYSFNO_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.setenv("CPHYSFNO_PLUGINS", "toy_components")
    here = str(Path(__file__).parent)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([here, os.environ.get("PYTHONPATH", "")]))
