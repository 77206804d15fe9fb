"""MkDocs hook: write ``reference/cli.md`` from the command line's own parser, so the
reference cannot drift from the code."""

from __future__ import annotations

import argparse

from mkdocs.structure.files import File

from cphysfno_core.app.cli import build_parser


def _help(parser: argparse.ArgumentParser) -> str:
    """A parser's help as argparse prints it, at a fixed width."""
    parser.formatter_class = lambda prog: argparse.HelpFormatter(prog, width=88)
    return parser.format_help().rstrip()


def render() -> str:
    """The command-line reference as Markdown: the top-level help, then each command's."""
    parser = build_parser()
    lines = [
        "# Command-line reference",
        "",
        "`cphysfno` runs a study from a config file, stage by stage or at once, and predicts",
        "with saved models. The text below is the parser's own help.",
        "",
        "```text",
        _help(parser),
        "```",
        "",
    ]
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, command in commands.choices.items():
        lines += [f"## `cphysfno {name}`", "", "```text", _help(command), "```", ""]
    return "\n".join(lines)


def on_files(files, config):
    """Add the generated page to the site."""
    files.append(File.generated(config, "reference/cli.md", content=render()))
