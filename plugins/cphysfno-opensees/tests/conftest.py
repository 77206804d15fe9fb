"""The plugin's tests import their shared helpers (``sac9_pulses``, ``script_models``) from
this folder, and share the fixtures of a test module's own script folder and frame."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import script_models as sm  # noqa: E402 - found through the path above


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A folder of scripts for the test module."""
    return tmp_path_factory.mktemp("scripts")


@pytest.fixture(scope="module")
def frame_script(folder):
    """The two-story frame of ``script_models.FRAME`` in SI units."""
    return sm.frame(folder)
