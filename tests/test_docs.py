"""The documentation site builds in strict mode, and its Python examples run.

Blocks fenced as ```python are executed, page by page in one namespace; blocks fenced as
```py are shown only (they need a cluster or a package that is not there).
"""

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

import cphysfno_core
from cphysfno_core.api.registry import get_registry

ROOT = Path(__file__).parents[1]
PAGES = sorted((ROOT / "docs").rglob("*.md"))
BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
PLUGIN_DIRS = sorted(p.parent for p in (ROOT / "plugins").glob("*/pyproject.toml"))


def _hook(name: str):
    """A module of docs/hooks, imported by path (the folder is not a package)."""
    spec = importlib.util.spec_from_file_location(
        f"docs_hook_{name}", ROOT / "docs" / "hooks" / f"{name}.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def plugin_pages():
    return _hook("plugin_pages")


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
    home = (tmp_path / "site" / "index.html").read_text()
    for dist in PLUGIN_DIRS:
        page = tmp_path / "site" / "plugins" / dist.name / "index.html"
        assert page.exists(), f"no page for plugins/{dist.name}"
        assert f'href="plugins/{dist.name}/"' in home, f"plugins/{dist.name} is not in the nav"
        assert "Registered components" in page.read_text()
    api = (tmp_path / "site" / "reference" / "api" / "index.html").read_text()
    compose = api[api.index('id="cphysfno_core.compose"') :]
    signature = re.sub(r"<[^>]+>", "", compose[: compose.index("</code></pre>")])
    assert "compose(" in signature and "operator: PartLike" in signature
    assert "-&gt; CompositeModel" in signature
    assert 'id="cphysfno_core.CompositeModel.predict"' in api
    assert 'id="cphysfno_core.testing.check_structure"' in api
    assert ":class:`" not in api and ":func:`" not in api


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


def test_the_readmes_python_runs_and_the_readme_stays_short(tmp_path, monkeypatch, capsys):
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 120
    blocks = BLOCK.findall(readme)
    assert blocks, "the README shows a runnable Python example"
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "README.md", "exec"), namespace)
    assert "relative L2 on the test records" in capsys.readouterr().out
    assert (tmp_path / "my-model" / "model.json").exists()


def test_every_plugin_has_a_page_in_the_nav(plugin_pages):
    assert plugin_pages.distributions() == PLUGIN_DIRS
    nav = yaml.load((ROOT / "mkdocs.yml").read_text(), Loader=yaml.BaseLoader)["nav"]
    section = next(item["Plugins"] for item in plugin_pages.fill_nav(nav) if "Plugins" in item)
    listed = [page for entry in section for page in entry.values()]
    assert listed[0] == "plugins/overview.md"
    assert sorted(listed[1:]) == [f"plugins/{d.name}.md" for d in PLUGIN_DIRS]
    again = plugin_pages.fill_nav(nav)  # filling twice lists each page once
    assert [p for e in again for p in e.get("Plugins", [])] == section


def test_each_plugin_page_is_its_readme_with_what_it_registers(plugin_pages):
    overview = plugin_pages.overview()
    for dist in PLUGIN_DIRS:
        page, _ = plugin_pages.render(dist)
        assert page.startswith(f"# {dist.name}\n"), f"plugins/{dist.name}/README.md title"
        assert f"({dist.name}.md)" in overview
        readme = (dist / "README.md").read_text()
        for entry in get_registry().entries():
            if entry.distribution.split(" ")[0] == dist.name:
                assert f"`{entry.name}`" in readme, f"{dist.name}: README never names {entry.name}"
                assert f"(../reference/config.md#{entry.name})" in page


def test_readme_links_work_from_the_site(plugin_pages, tmp_path, monkeypatch):
    docs, plugins = tmp_path / "docs", tmp_path / "plugins"
    dist = plugins / "cphysfno-x"
    (dist / "figures").mkdir(parents=True)
    (dist / "figures" / "loops.png").write_bytes(b"png")
    monkeypatch.setattr(plugin_pages, "ROOT", tmp_path)
    monkeypatch.setattr(plugin_pages, "DOCS", docs)
    monkeypatch.setattr(plugin_pages, "PLUGINS", plugins)
    readme = "\n".join(
        [
            "[install](../../docs/install.md#cpu) and [FNO](../cphysfno-fno/README.md)",
            "![loops](figures/loops.png) [pypi](https://pypi.org/project/x/) [top](#x)",
            "[the model](src/x/model.py) [`src/x/law.py`](src/x/law.py)",
            "```toml",
            "[kept](src/x/model.py)",
            "```",
            "`[kept](src/x/model.py)`",
        ]
    )
    text, assets = plugin_pages.rewrite_links(readme, dist)
    lines = text.splitlines()
    assert lines[0] == "[install](../install.md#cpu) and [FNO](cphysfno-fno.md)"
    assert (
        lines[1]
        == "![loops](cphysfno-x/figures/loops.png) [pypi](https://pypi.org/project/x/) [top](#x)"
    )
    assert (
        lines[2]
        == "the model (`plugins/cphysfno-x/src/x/model.py`) `plugins/cphysfno-x/src/x/law.py`"
    )
    assert lines[3:] == readme.splitlines()[3:]
    assert assets == {"plugins/cphysfno-x/figures/loops.png": dist / "figures" / "loops.png"}
    linked, _ = plugin_pages.rewrite_links("[the model](src/x/model.py)", dist, "https://h/o/r/")
    assert linked == "[the model](https://h/o/r/blob/HEAD/plugins/cphysfno-x/src/x/model.py)"


def test_a_plugin_without_a_readme_fails_the_build(plugin_pages, tmp_path):
    from mkdocs.exceptions import PluginError

    with pytest.raises(PluginError, match="has no README.md"):
        plugin_pages.render(tmp_path / "cphysfno-empty")


def test_every_public_name_is_in_the_api_reference():
    api = (ROOT / "docs" / "reference" / "api.md").read_text()
    directives = set(re.findall(r"^::: ([\w.]+)", api, re.M))
    missing = [
        name
        for name in cphysfno_core.__all__
        if f"cphysfno_core.{name}" not in directives
        and getattr(getattr(cphysfno_core, name), "__name__", None) not in directives
    ]
    assert not missing, f"add ::: cphysfno_core.<name> to docs/reference/api.md for {missing}"


def test_sphinx_roles_become_code_spans():
    roles = _hook("sphinx_roles")
    text = ":class:`~cphysfno_core.CompositeModel`, :func:`.compose`, :meth:`fit`, :mod:`a.b`"
    assert roles.convert(text) == "`CompositeModel`, `compose()`, `fit()`, `a.b`"
