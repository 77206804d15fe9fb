"""MkDocs hook: publish every plugin distribution's ``plugins/<dist>/README.md`` as the
site's ``plugins/<dist>.md``, with an overview page and the nav section "Plugins", so a
plugin's page is its README and cannot drift from it.

Relative links in a README are written for the repository (``plugins/<dist>/``); on the
site they are rewritten: to a documentation page (``../../docs/install.md``), to another
plugin's page (``../cphysfno-fno/README.md``), to an image published beside the page, or
to the file in the repository (``repo_url``); without a ``repo_url`` a link to a source file
becomes its text and its path. Each page ends with the components the distribution
registers, read from the registry, linked to their parameters in the configuration
reference.
"""

from __future__ import annotations

import posixpath
import re
import tomllib
from pathlib import Path
from urllib.parse import unquote, urlsplit

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

from cphysfno_core.api.registry import get_registry

ROOT = Path(__file__).parents[2]
DOCS = ROOT / "docs"
PLUGINS = ROOT / "plugins"
PAGE_DIR = "plugins"
"""Where the generated pages live in the site, relative to ``docs/``."""
OVERVIEW = f"{PAGE_DIR}/overview.md"
SECTION = "Plugins"
"""Title of the nav section the pages are listed in."""
CONFIG_REFERENCE = "reference/config.md"
IMAGES = {".png", ".jpg", ".jpeg", ".gif", ".svg", ".webp"}

TOKENS = re.compile(
    r"(?P<fence>^(?P<marker>```|~~~)[^\n]*\n.*?^(?P=marker)[ \t]*$)"
    r"|(?P<code>(?P<ticks>`+)[^\n]*?(?P=ticks))"
    r"|(?P<link>(?P<bang>!?)\[(?P<text>[^\]\n]*)\]\((?P<target>[^)\s]+)(?P<title>\s+\"[^\"]*\")?\))",
    re.S | re.M,
)
"""Fenced code, inline code (both left as they are) and inline links or images."""


def distributions() -> list[Path]:
    """The plugin distributions' folders: every ``plugins/<dist>`` with a ``pyproject.toml``."""
    return sorted(p.parent for p in PLUGINS.glob("*/pyproject.toml"))


def page_uri(dist: Path) -> str:
    """The site page of a distribution, relative to ``docs/``."""
    return f"{PAGE_DIR}/{dist.name}.md"


def description(dist: Path) -> str:
    """The distribution's one-line description from its ``pyproject.toml``."""
    project = tomllib.loads((dist / "pyproject.toml").read_text())["project"]
    return project.get("description", "")


def _within(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents


def _target(target: str, dist: Path, repo_url: str | None, assets: dict[str, Path]) -> str | None:
    """Where a README's link points on the site (``target`` itself when absolute), or None
    when it names a repository file and there is no repository to link to."""
    split = urlsplit(target)
    if split.scheme or split.netloc or not split.path or target.startswith("/"):
        return target
    fragment = f"#{split.fragment}" if split.fragment else ""
    path = (dist / unquote(split.path)).resolve()
    if _within(path, DOCS):
        relative = path.relative_to(DOCS).as_posix()
        return posixpath.relpath(relative, PAGE_DIR) + fragment
    if path.name == "README.md" and path.parent.parent == PLUGINS:
        return f"{path.parent.name}.md{fragment}"
    if _within(path, dist) and path.suffix.lower() in IMAGES and path.is_file():
        local = f"{dist.name}/{path.relative_to(dist).as_posix()}"
        assets[f"{PAGE_DIR}/{local}"] = path
        return local
    if repo_url and _within(path, ROOT):
        return f"{repo_url.rstrip('/')}/blob/HEAD/{path.relative_to(ROOT).as_posix()}{fragment}"
    return None


def rewrite_links(
    markdown: str, dist: Path, repo_url: str | None = None
) -> tuple[str, dict[str, Path]]:
    """A README's Markdown with its relative links made to work from the site page, and the
    images it shows from its own folder (``{site path: file}``) to publish beside it."""
    assets: dict[str, Path] = {}

    def replace(match: re.Match[str]) -> str:
        if not match["link"]:
            return match[0]
        target = _target(match["target"], dist, repo_url, assets)
        if target is not None:
            title = match["title"] or ""
            return f"{match['bang']}[{match['text']}]({target}{title})"
        path = (dist / unquote(urlsplit(match["target"]).path)).resolve()
        where = path.relative_to(ROOT).as_posix() if _within(path, ROOT) else match["target"]
        text = match["text"].strip("`")
        return f"`{where}`" if text in (where, match["target"]) else f"{match['text']} (`{where}`)"

    return TOKENS.sub(replace, markdown), assets


def _components_section(dist: Path) -> list[str]:
    """The components the installed distribution registers, as Markdown."""
    entries = [e for e in get_registry().entries() if e.distribution.split(" ")[0] == dist.name]
    reference = posixpath.relpath(CONFIG_REFERENCE, PAGE_DIR)
    lines = ["", "## Registered components", ""]
    if not entries:
        return lines + [
            f"`{dist.name}` was not installed where this site was built; install it with",
            f"`pip install -e plugins/{dist.name}`.",
            "",
        ]
    lines += [
        f"What `{dist.name}` registers through the `cphysfno` entry point, as installed where",
        "this site was built. Each name links to its parameters, as the code declares them,",
        f"in the [configuration reference]({reference}).",
        "",
        "| kind | name | class |",
        "|---|---|---|",
    ]
    for e in entries:
        path = f"{e.cls.__module__}.{e.cls.__qualname__}"
        lines.append(f"| `{e.kind}` | [`{e.name}`]({reference}#{e.name}) | `{path}` |")
    return lines + [""]


def render(dist: Path, repo_url: str | None = None) -> tuple[str, dict[str, Path]]:
    """A distribution's page (its README, links rewritten, then its registered components)
    and the images to publish beside it.

    Raises:
        PluginError: the distribution has no README.md.
    """
    readme = dist / "README.md"
    if not readme.is_file():
        raise PluginError(f"plugins/{dist.name} has no README.md: every plugin needs one")
    markdown, assets = rewrite_links(readme.read_text(), dist, repo_url)
    return markdown.rstrip() + "\n" + "\n".join(_components_section(dist)), assets


def overview() -> str:
    """The overview page: every distribution, what it is and what it registers."""
    registered: dict[str, list[str]] = {}
    for e in get_registry().entries():
        registered.setdefault(e.distribution.split(" ")[0], []).append(f"`{e.name}` ({e.kind})")
    lines = [
        "# Plugins",
        "",
        "Every structure, ground-motion source, physics preprocessor, neural operator, refiner",
        "and story law is a plugin: a distribution under `plugins/` that registers its",
        "components through the `cphysfno` entry point, exactly as a third party's would",
        "(see [Writing a plugin](../plugins.md)). Each page below is the distribution's README.",
        "",
        "| distribution | what | components |",
        "|---|---|---|",
    ]
    for dist in distributions():
        names = ", ".join(registered.get(dist.name, [])) or "not installed here"
        what = description(dist).replace("|", "\\|")
        lines.append(f"| [`{dist.name}`]({dist.name}.md) | {what} | {names} |")
    return "\n".join(lines) + "\n"


def nav_entries() -> list[dict[str, str]]:
    """The nav section's pages: the overview, then one page per distribution."""
    return [{"Overview": OVERVIEW}] + [{d.name: page_uri(d)} for d in distributions()]


def fill_nav(nav: list) -> list:
    """``nav`` with its "Plugins" section listing every page (appended if absent); pages
    already listed there stay where they are."""
    section = next((item for item in nav if isinstance(item, dict) and SECTION in item), None)
    if section is None:
        section = {SECTION: []}
        nav.append(section)
    pages = section[SECTION] if isinstance(section[SECTION], list) else [section[SECTION]]
    listed = {
        value
        for page in pages
        for value in (page.values() if isinstance(page, dict) else [page])
        if isinstance(value, str)
    }
    section[SECTION] = pages + [e for e in nav_entries() if next(iter(e.values())) not in listed]
    return nav


def on_config(config):
    """List the plugin pages in the nav."""
    if config.nav is not None:
        fill_nav(config.nav)
    return config


def on_files(files, config):
    """Add the overview, every plugin's page and the images they show to the site."""
    files.append(File.generated(config, OVERVIEW, content=overview()))
    for dist in distributions():
        markdown, assets = render(dist, config.repo_url)
        files.append(File.generated(config, page_uri(dist), content=markdown))
        for uri, path in assets.items():
            files.append(File.generated(config, uri, content=path.read_bytes()))
    return files


def on_serve(server, config, builder):
    """Rebuild when a README changes under ``mkdocs serve``."""
    for dist in distributions():
        server.watch(str(dist / "README.md"))
    return server
