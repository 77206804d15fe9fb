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
