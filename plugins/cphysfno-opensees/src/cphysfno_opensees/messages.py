"""What OpenSees prints, captured while a record is analysed.

OpenSeesPy writes its warnings through Python's ``sys.stdout`` and ``sys.stderr`` (``WARNING:
DO NOT USE THE "Bilin" MATERIAL`` whenever a model with that material is built, five lines
of Newton's complaints at every step that needs a fallback). :func:`recording` keeps them
for the record being analysed; :func:`captured` keeps them for an error message of its own
and passes them on to the recording around it. The runner sends each record's text back
with its result, and the data generation counts them (``cphysfno_core.data.messages``).
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Iterator

_RECORDINGS: list[io.StringIO] = []


@contextlib.contextmanager
def recording() -> Iterator[io.StringIO]:
    """Everything printed inside, kept in the buffer it yields (nothing reaches the
    terminal), including what a :func:`captured` block inside prints."""
    buffer = io.StringIO()
    _RECORDINGS.append(buffer)
    try:
        with contextlib.redirect_stderr(buffer), contextlib.redirect_stdout(buffer):
            yield buffer
    finally:
        _RECORDINGS.pop()


@contextlib.contextmanager
def captured() -> Iterator[io.StringIO]:
    """OpenSees' messages (and anything else printed) kept in a buffer instead of shown, for
    an error message to quote (:func:`said`); passed on to the :func:`recording` around
    it, if any, when the block ends."""
    buffer = io.StringIO()
    try:
        with contextlib.redirect_stderr(buffer), contextlib.redirect_stdout(buffer):
            yield buffer
    finally:
        if _RECORDINGS:
            _RECORDINGS[-1].write(buffer.getvalue())


def said(buffer: io.StringIO, lines: int = 8) -> str:
    """The last ``lines`` non-empty lines OpenSees printed, indented, or nothing."""
    text = [line for line in buffer.getvalue().splitlines() if line.strip()]
    if not text:
        return ""
    return "\nOpenSees said:\n" + "\n".join(f"  {line.strip()}" for line in text[-lines:])
