"""The documentation site builds in strict mode, and its Python examples run.

Blocks fenced as ```python are executed, page by page in one namespace; blocks fenced as
```py are shown only (they need a cluster or a package that is not there).
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
PAGES = sorted((ROOT / "docs").rglob("*.md"))
BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def test_site_builds_in_strict_mode(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(tmp_path / "site")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert (tmp_path / "site" / "reference" / "config" / "index.html").exists()
    config_page = (tmp_path / "site" / "reference" / "config" / "index.html").read_text()
    assert "bouc-wen-shear-building" in config_page and "learning_rate" in config_page
    assert "group_by" in config_page and "ground_motion_input" in config_page
    cli_page = (tmp_path / "site" / "reference" / "cli" / "index.html").read_text()
    for command in ("plugins", "run", "generate", "train", "evaluate", "predict", "study"):
        assert f"cphysfno {command}</code>" in cli_page
    assert "--verbose" in cli_page and "--markdown" in cli_page
    results = (tmp_path / "site" / "benchmarks" / "index.html").read_text()
    assert "Benchmark results" in results and "Reliability" in results
    examples = (tmp_path / "site" / "results" / "index.html").read_text()
    assert "example2.json" in examples and 'src="../example1-layers.png"' in examples
    assert (tmp_path / "site" / "example1-layers.png").exists()


@pytest.mark.parametrize(
    "page",
    [p for p in PAGES if BLOCK.search(p.read_text())],
    ids=lambda p: str(p.relative_to(ROOT / "docs")),
)
def test_python_examples_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for block in BLOCK.findall(page.read_text()):
        exec(compile(block, str(page), "exec"), namespace)
