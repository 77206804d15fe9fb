"""MkDocs hook: publish ``benchmarks/RESULTS.md`` as the site's ``benchmarks.md`` page, so
the site shows the recorded measurements themselves rather than a copy that could age."""

from __future__ import annotations

from pathlib import Path

from mkdocs.structure.files import File

RESULTS = Path(__file__).parents[2] / "benchmarks" / "RESULTS.md"


def on_files(files, config):
    """Add the results page to the site."""
    files.append(File.generated(config, "benchmarks.md", content=RESULTS.read_text()))
    return files
