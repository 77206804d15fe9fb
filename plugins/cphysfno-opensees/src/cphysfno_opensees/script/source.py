"""A user's OpenSeesPy script: found, executed as a module, its functions looked up."""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import sys
import traceback
from collections.abc import Callable, Mapping, Sequence
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


def function(module: ModuleType, path: Path, name: str) -> Callable[..., object]:
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


def call(module: ModuleType, path: Path, name: str, arguments: Mapping[str, float]) -> None:
    """Call the script's function ``name`` with the keywords of ``arguments`` it accepts
    (:func:`accepted`; numbers in the script's units).

    Raises:
        ScriptError: it raises; the message names the script, the function and the
            lines of the script in the traceback.
    """
    target = function(module, path, name)
    try:
        target(**accepted(target, arguments))
    except Exception as error:  # noqa: BLE001 - the user's code: any exception is theirs
        raise ScriptError(
            f"{name}() of OpenSees script {path} raised {type(error).__name__}: {error}\n"
            f"{_their_traceback(error, path)}"
        ) from None


def keywords(target: Callable[..., object]) -> tuple[str, ...] | None:
    """The names ``target`` can be given as keywords, in its signature's order; None if it
    takes any keyword (``**kwargs``)."""
    names = []
    for parameter in inspect.signature(target).parameters.values():
        if parameter.kind is parameter.VAR_KEYWORD:
            return None
        if parameter.kind in (parameter.POSITIONAL_OR_KEYWORD, parameter.KEYWORD_ONLY):
            names.append(parameter.name)
    return tuple(names)


def accepted(target: Callable[..., object], arguments: Mapping[str, float]) -> dict[str, float]:
    """The keywords of ``arguments`` that ``target``'s signature accepts (all of them if it
    takes ``**kwargs``)."""
    names = keywords(target)
    return {key: value for key, value in arguments.items() if names is None or key in names}


def check_arguments(
    module: ModuleType, path: Path, names: Sequence[str], arguments: Mapping[str, float]
) -> None:
    """Check that each keyword of ``arguments`` is accepted by at least one of the script's
    functions ``names`` (``build`` and the gravity function).

    Raises:
        ScriptError: a function is missing, or a keyword is accepted by none of them; the
            message names the keywords, the script and the parameters the functions take.
    """
    if not arguments:
        return
    targets = {name: function(module, path, name) for name in names}
    taken = set().union(*(accepted(target, arguments) for target in targets.values()))
    unknown = [key for key in arguments if key not in taken]
    if unknown:
        signatures = ", ".join(
            f"{name}({', '.join(keywords(target) or ())})" for name, target in targets.items()
        )
        raise ScriptError(
            f"arguments: {', '.join(unknown)}: no parameter of "
            f"{' or '.join(f'{name}()' for name in names)} of OpenSees script {path} "
            f"takes {'it' if len(unknown) == 1 else 'them'}; they take {signatures}"
        )


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
