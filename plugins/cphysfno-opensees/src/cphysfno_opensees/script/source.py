"""A user's OpenSeesPy script: found, executed as a module, its functions looked up."""

from __future__ import annotations

import hashlib
import importlib.util
import sys
import traceback
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

from cphysfno_core import ConfigError

from ..loader import import_opensees

BUILD = "build"
"""The function every script defines: it creates the model in OpenSees' domain."""


class ScriptError(ConfigError):
    """A user's OpenSees model that cannot be used as it is: its script is missing, raises,
    lacks a function, names a node the model does not have, or its gravity analysis
    fails. The message names the script and says what to change."""


def resolve(script: str | Path) -> Path:
    """The absolute path of ``script`` (relative paths from the working directory).

    Raises:
        ScriptError: there is no such file.
    """
    path = Path(script).expanduser()
    if not path.is_absolute():
        path = Path.cwd() / path
    path = path.resolve()
    if not path.is_file():
        raise ScriptError(
            f"OpenSees script {script}: no such file ({path}); a relative path is taken "
            "from the working directory"
        )
    return path


_LOADED: dict[tuple[Path, int, int], ModuleType] = {}


def load(path: Path) -> ModuleType:
    """The script at ``path`` executed as a module (once per process and version of the
    file), after OpenSeesPy has been made importable (:func:`~..loader.import_opensees`),
    so that the script's own ``import openseespy.opensees as ops`` works.

    Raises:
        ScriptError: the file is missing, raises while it is executed, or defines no
            ``build()``.
    """
    import_opensees()
    try:
        status = path.stat()
    except OSError as error:
        raise ScriptError(f"OpenSees script {path}: {error.strerror}") from None
    key = (path, status.st_mtime_ns, status.st_size)
    if key in _LOADED:
        return _LOADED[key]
    digest = hashlib.sha1(str(path).encode()).hexdigest()[:12]
    name = f"_cphysfno_opensees_script_{digest}"
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ScriptError(f"OpenSees script {path}: not a Python file")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as error:  # noqa: BLE001 - the user's code: any exception is theirs
        del sys.modules[name]
        raise ScriptError(
            f"OpenSees script {path} raised {type(error).__name__} while it was executed: "
            f"{error}\n{_their_traceback(error, path)}"
        ) from None
    function(module, path, BUILD)
    _LOADED[key] = module
    return module


def function(module: ModuleType, path: Path, name: str) -> Callable[[], object]:
    """The function ``name`` the script defines.

    Raises:
        ScriptError: it defines none of that name, or it is not callable.
    """
    found = getattr(module, name, None)
    if found is None:
        what = "the model" if name == BUILD else "the gravity loads"
        raise ScriptError(
            f"OpenSees script {path} defines no function {name}() (it must define "
            f"{name}() to create {what})"
        )
    if not callable(found):
        raise ScriptError(f"OpenSees script {path}: {name} is not a function")
    return found


def call(module: ModuleType, path: Path, name: str) -> None:
    """Call the script's function ``name()``.

    Raises:
        ScriptError: it raises; the message names the script, the function and the
            lines of the script in the traceback.
    """
    target = function(module, path, name)
    try:
        target()
    except Exception as error:  # noqa: BLE001 - the user's code: any exception is theirs
        raise ScriptError(
            f"{name}() of OpenSees script {path} raised {type(error).__name__}: {error}\n"
            f"{_their_traceback(error, path)}"
        ) from None


def _their_traceback(error: BaseException, path: Path) -> str:
    """The frames of ``error``'s traceback in the script's file, one line each."""
    frames = [
        f"  {Path(frame.filename).name}, line {frame.lineno}: {frame.line}"
        for frame in traceback.extract_tb(error.__traceback__)
        if Path(frame.filename) == path
    ]
    if isinstance(error, SyntaxError) and error.lineno is not None:
        frames.append(f"  {path.name}, line {error.lineno}: {(error.text or '').strip()}")
    return "\n".join(frames)
