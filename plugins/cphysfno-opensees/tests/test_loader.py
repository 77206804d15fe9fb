"""OpenSeesPy imports through the plugin's loader on a machine without system BLAS."""

from __future__ import annotations

import subprocess
import sys

import pytest
from cphysfno_opensees import loader

from cphysfno_core import PluginError


def test_import_opensees_runs_an_analysis_in_a_fresh_interpreter():
    # A fresh process: the libraries must be found by the loader, not by an earlier import.
    script = (
        "from cphysfno_opensees.loader import import_opensees\n"
        "ops = import_opensees()\n"
        "ops.wipe(); ops.model('basic', '-ndm', 1, '-ndf', 1)\n"
        "ops.node(1, 0.0); ops.node(2, 0.0, '-mass', 2.0); ops.fix(1, 1)\n"
        "ops.uniaxialMaterial('Elastic', 1, 8.0)\n"
        "ops.element('zeroLength', 1, 1, 2, '-mat', 1, '-dir', 1)\n"
        "print(ops.eigen('-fullGenLapack', 1)[0])\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert float(out.stdout.strip().splitlines()[-1]) == pytest.approx(4.0)  # k / m


def test_missing_openseespy_is_one_line_saying_how_to_fix(monkeypatch):
    def refuse(name):
        raise ImportError(f"No module named '{name}'")

    monkeypatch.setattr(loader.importlib.util, "find_spec", lambda name: None)
    monkeypatch.setattr(loader.importlib, "import_module", refuse)
    with pytest.raises(PluginError, match="pip install") as caught:
        loader.import_opensees()
    assert "\n" not in str(caught.value)
