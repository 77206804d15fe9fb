"""MkDocs hook: publish the recorded measurements themselves rather than copies that could
age: ``benchmarks/RESULTS.md`` as the site's ``benchmarks.md`` page, and ``results/README.md``
as ``results.md`` with the figures beside it."""

from __future__ import annotations

from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).parents[2]
PAGES = {
    "benchmarks.md": ROOT / "benchmarks" / "RESULTS.md",
    "results.md": ROOT / "results" / "README.md",
}
FIGURES = ROOT / "results"


def on_files(files, config):
    """Add the two pages and the results' figures to the site."""
    for page, source in PAGES.items():
        files.append(File.generated(config, page, content=source.read_text()))
    for figure in sorted(FIGURES.glob("*.png")):
        files.append(File.generated(config, figure.name, content=figure.read_bytes()))
    return files
