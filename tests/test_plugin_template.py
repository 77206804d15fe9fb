"""A third-party plugin installed beside cphysfno is found, listed and used by name.

The template in ``examples/plugin-template`` is copied and installed into a temporary
folder (the shared environment is left as it is); the subprocesses below see it on
``PYTHONPATH``, as they would see any installed distribution.
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

TEMPLATE = Path(__file__).parents[1] / "examples" / "plugin-template"
DISTRIBUTION = "cphysfno-plugin-template 0.1.0"

STUDY = """
[structure]
name = "duffing-chain"

[ground_motion]
name = "kanai-tajimi"
duration = 2.0

[[preprocessor]]
name = "els"

[[preprocessor]]
name = "modal"
modes = 2

[operator]
name = "fno"
layers = 2
modes = 8
width = 8
projection_width = 16

[data]
n_train = 8
n_val = 4
n_test = 4
chunk_size = 8
executor = "serial"

[training]
epochs = 2
batch_size = 4

[output]
figures = false
"""


@pytest.fixture(scope="module")
def template(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    """A copy of the template, and an environment in which it is installed."""
    work = tmp_path_factory.mktemp("plugin-template")
    source = work / "source"
    ignore = shutil.ignore_patterns("*.egg-info", "build", "__pycache__", ".*_cache")
    shutil.copytree(TEMPLATE, source, ignore=ignore)
    site = work / "site"
    install = [sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check"]
    options = ["--no-deps", "--no-build-isolation", "--no-index", "--target", str(site)]
    result = subprocess.run([*install, *options, str(source)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-3000:]
    environment = {
        key: value
        for key, value in os.environ.items()
        if key not in ("CPHYSFNO_DISABLE_PLUGIN_AUTOLOAD", "CPHYSFNO_PLUGINS")
    }
    path = [str(site), *filter(None, [os.environ.get("PYTHONPATH")])]
    environment["PYTHONPATH"] = os.pathsep.join(path)
    return source, environment


def cphysfno(environment: dict[str, str], *args: str) -> subprocess.CompletedProcess:
    """``cphysfno *args`` in a subprocess that sees ``environment``."""
    return subprocess.run(
        [sys.executable, "-m", "cphysfno_core.app.cli", *args],
        capture_output=True,
        text=True,
        env=environment,
    )


def listed(listing: str) -> dict[tuple[str, str], str]:
    """``(kind, name) -> distribution`` from the text of ``cphysfno plugins``."""
    found = {}
    kind = ""
    for line in listing.splitlines():
        if not line.startswith(" ") and line.endswith(":"):
            kind = line[:-1]
        elif kind in ("structure", "ground_motion") and line.strip():
            name, _, rest = line.strip().partition(" ")
            if not name.startswith("parameters:"):
                found[(kind, name)] = rest.strip()
    return found


def test_plugins_lists_both_components_with_the_distribution(template):
    _, environment = template
    result = cphysfno(environment, "plugins")
    assert result.returncode == 0, result.stderr[-3000:]
    components = listed(result.stdout)
    assert components[("structure", "duffing-chain")] == DISTRIBUTION
    assert components[("ground_motion", "kanai-tajimi")] == DISTRIBUTION
    assert "broken:" not in result.stdout or DISTRIBUTION not in result.stdout.split("broken:")[1]


def test_a_study_runs_with_the_components_by_name(template, tmp_path):
    _, environment = template
    config = tmp_path / "study.toml"
    config.write_text(STUDY)
    out = tmp_path / "out"
    result = cphysfno(environment, "run", str(config), "--out", str(out))
    assert result.returncode == 0, result.stderr[-3000:]
    models = json.loads((out / "metrics.json").read_text())["models"]
    assert set(models) == {
        "fno",
        "c-physfno-els",
        "c-physfno-modal",
        "physics-els",
        "physics-modal",
    }
    for row in models.values():
        assert len(row["rel_l2"]) == 3 and np.isfinite(row["rel_l2"]).all()


def test_the_templates_own_tests_pass(template):
    source, environment = template
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"],
        capture_output=True,
        text=True,
        env=environment,
        cwd=source,
    )
    assert result.returncode == 0, result.stdout[-3000:]
