"""Exception types a user can trigger. Every message says what to change."""

from __future__ import annotations

import ast
import inspect
import sys
from pathlib import Path


class CphysfnoError(Exception):
    """Base class of every error this package raises on purpose."""


class ConfigError(CphysfnoError, ValueError):
    """A configuration field is missing, unknown or out of range."""


class RegistryError(CphysfnoError, LookupError):
    """A component name is unknown, taken twice, or its plugin failed to load."""


class InputError(CphysfnoError, ValueError):
    """An array handed to the framework has the wrong shape, NaN/Inf, or a bad time step."""


class CapabilityError(CphysfnoError, TypeError):
    """A component needs a capability that another component does not provide."""


class DatasetError(CphysfnoError, OSError):
    """A dataset file is missing, incomplete or does not match the configuration."""


class NotFittedError(CphysfnoError, RuntimeError):
    """A component was used before ``fit``."""


class PluginError(CphysfnoError, RuntimeError):
    """A plugin broke its contract (for example returned an array of the wrong shape)."""


class MainGuardError(CphysfnoError, RuntimeError):
    """Worker processes were asked for from a script's top-level code, which every worker
    would run again."""


def check_main_guard(what: str) -> None:
    """Raise :class:`MainGuardError` if this call comes from the top-level code of the
    script being run (``python script.py``).

    Worker processes start by importing that script again; code outside an
    ``if __name__ == "__main__":`` block would then run in each of them and start workers
    of its own, which Python stops with a traceback of its internals. Call this before
    starting worker processes. Interactive sessions and ``python -c`` have no script to
    import, and pass.

    Args:
        what: what is about to start workers, for the message.
    """
    main = sys.modules.get("__main__")
    script = getattr(main, "__file__", None)
    if script is None:
        return
    frame = inspect.currentframe()
    while frame is not None:
        at_top = frame.f_code.co_name == "<module>" and frame.f_globals is vars(main)
        if at_top and not _guarded(script, frame.f_lineno):
            raise MainGuardError(
                f"{what} starts worker processes, and it was called from the top level of "
                f"{script} (line {frame.f_lineno}), which each worker would run again: put "
                'the script\'s code under `if __name__ == "__main__":` (or set the number '
                "of workers to 1)"
            )
        frame = frame.f_back


def _guarded(script: str, line: int) -> bool:
    """Whether ``line`` of ``script`` lies in an ``if __name__ == "__main__":`` block (an
    unreadable script counts as guarded: nothing is known against it)."""
    try:
        tree = ast.parse(Path(script).read_text())
    except (OSError, SyntaxError, ValueError):
        return True
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and _is_main_test(node.test):
            if node.body[0].lineno <= line <= (node.body[-1].end_lineno or line):
                return True
    return False


def _is_main_test(test: ast.expr) -> bool:
    """``__name__ == "__main__"`` (either way round)."""
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1):
        return False
    if not isinstance(test.ops[0], ast.Eq):
        return False
    sides = [test.left, test.comparators[0]]
    names = [s.id for s in sides if isinstance(s, ast.Name)]
    values = [s.value for s in sides if isinstance(s, ast.Constant)]
    return names == ["__name__"] and values == ["__main__"]


class CphysfnoWarning(UserWarning):
    """Something was done only in part (fewer records, a looser match): the message says
    what and why."""


class ExtrapolationWarning(CphysfnoWarning):
    """Records lie far outside what a model was trained on, so its predictions for them
    are extrapolations."""
