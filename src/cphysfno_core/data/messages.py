"""What a simulator printed while it analysed records, counted by distinct message.

A structure may return, in :attr:`~cphysfno_core.Responses.messages`, the text its
simulator printed for each record (OpenSees: a warning when a model is built, Newton's
complaints at every step that needs a fallback). Over a generation of thousands of records
the same few messages repeat thousands of times; :func:`summary` shows each once with its
count, the numbers in it (times, norms, iterations) written ``#`` so that one message at
different times counts as one.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Iterable, Mapping

_NUMBER = re.compile(r"(?<![\w^])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
"""A number standing alone (not the digits of a name such as ``Steel01`` or a unit's
power such as ``m/s^2``)."""


def message_of(line: str) -> str:
    """The distinct message a printed line is an instance of: stripped, its numbers
    written ``#``, runs of blanks made one (``"failed at time 3.45"`` -> ``"failed at time
    #"``)."""
    return " ".join(_NUMBER.sub("#", line).split())


def tally(texts: Iterable[str]) -> Counter[str]:
    """How many times each distinct message (:func:`message_of`) was printed in ``texts``
    (each what one record's analysis printed); blank lines are not messages."""
    counts: Counter[str] = Counter()
    for text in texts:
        counts.update(message_of(line) for line in text.splitlines() if line.strip())
    return counts


def summary(texts: Mapping[int, str], limit: int = 20) -> str:
    """The distinct messages of ``texts`` (record index -> what the simulator printed while
    analysing it), most frequent first, each once with how many times it was printed and
    in how many records; at most ``limit`` of them, then how many more. Empty when
    nothing was printed."""
    counts: Counter[str] = Counter()
    records: Counter[str] = Counter()
    for text in texts.values():
        own = tally([text])
        counts.update(own)
        records.update(own.keys())
    if not counts:
        return ""
    lines = [f"the simulator printed {len(counts)} distinct messages (numbers written #):"]
    for message, count in counts.most_common(limit):
        lines.append(f"  {count:>7} times in {records[message]:>5} records: {message}")
    if len(counts) > limit:
        lines.append(f"  ... and {len(counts) - limit} more distinct messages")
    return "\n".join(lines)


def full_log(texts: Mapping[int, str]) -> str:
    """Every record's text in full, in record order, each under ``record N:``."""
    blocks = [f"record {index}:\n{texts[index].rstrip()}\n" for index in sorted(texts)]
    return "\n".join(blocks)
