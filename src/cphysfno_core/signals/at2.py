"""Reader of PEER NGA-West2 ``.AT2`` acceleration files.

The format: four header lines, then the samples in g, several per line::

    PEER NGA STRONG MOTION DATABASE RECORD
    Imperial Valley-06, 10/15/1979, El Centro Array #6, 233
    ACCELERATION TIME SERIES IN UNITS OF G
    NPTS=  7807, DT=   .0050 SEC
      .1234E-02  .2345E-02 ...

The older NGA-West1 layout of the fourth line (``7807    .0050    NPTS, DT``) is read too.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .errors import DatasetError
from .histories import Record
from .intensity import STANDARD_GRAVITY

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?")
_NPTS_DT = re.compile(
    r"NPTS\s*=\s*(?P<npts>\d+)\s*,?\s*DT\s*=\s*(?P<dt>" + _NUMBER.pattern + r")", re.IGNORECASE
)
_OLD_NPTS_DT = re.compile(
    r"^\s*(?P<npts>\d+)\s+(?P<dt>" + _NUMBER.pattern + r")\s+NPTS\s*,\s*DT", re.IGNORECASE
)
HEADER_LINES = 4


def _fail(path: Path, line: int, message: str) -> DatasetError:
    return DatasetError(f"{path}, line {line}: {message}")


def _title_fields(title: str) -> dict[str, str]:
    """Event, date, station and component from an NGA-West2 title line, where present."""
    parts = [p.strip() for p in title.split(",")]
    if len(parts) < 4:
        return {"title": title.strip()}
    return {
        "title": title.strip(),
        "event": parts[0],
        "date": parts[1],
        "station": ", ".join(parts[2:-1]),
        "component": parts[-1],
    }


def read_at2(path: str | Path) -> Record:
    """Read one AT2 file into a :class:`Record` in m/s^2 (the file's g times 9.80665).

    Raises:
        DatasetError: naming the file and line, for a missing or unreadable file, a header
            that is not the PEER one (units other than g, no NPTS and DT), a value that is
            not a number, a non-positive DT, or a sample count other than NPTS.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as error:
        raise DatasetError(f"{path}: cannot read the AT2 file ({error.strerror})") from None
    if len(lines) < HEADER_LINES:
        raise _fail(
            path, len(lines) + 1, f"the header ends early: an AT2 file has {HEADER_LINES} lines"
        )
    if "UNITS OF G" not in lines[2].upper():
        raise _fail(
            path,
            3,
            f"expected acceleration in units of g ('ACCELERATION TIME SERIES IN UNITS OF G'), "
            f"found {lines[2].strip()!r}",
        )
    found = _NPTS_DT.search(lines[3]) or _OLD_NPTS_DT.search(lines[3])
    if found is None:
        raise _fail(
            path, 4, f"expected 'NPTS= <count>, DT= <seconds> SEC', found {lines[3].strip()!r}"
        )
    npts = int(found["npts"])
    dt = float(found["dt"].replace("D", "E").replace("d", "e"))
    if not np.isfinite(dt) or dt <= 0.0:
        raise _fail(path, 4, f"DT must be > 0 s, found {found['dt']}")
    values: list[float] = []
    for number, line in enumerate(lines[HEADER_LINES:], start=HEADER_LINES + 1):
        for chunk in line.split():
            if _NUMBER.sub("", chunk):
                raise _fail(path, number, f"{chunk!r} is not a number")
        tokens = _NUMBER.findall(line)
        if len(values) + len(tokens) > npts:
            raise _fail(path, number, f"more samples than NPTS = {npts}")
        values.extend(float(t.replace("D", "E").replace("d", "e")) for t in tokens)
    if len(values) < npts:
        raise _fail(
            path,
            len(lines),
            f"the file ends after {len(values)} samples but NPTS = {npts}: it is truncated",
        )
    acceleration = np.asarray(values) * STANDARD_GRAVITY
    if not np.all(np.isfinite(acceleration)):
        raise DatasetError(f"{path}: holds a sample that is not finite")
    metadata = {"name": path.name, "file": str(path), **_title_fields(lines[1])}
    return Record(acceleration, dt, metadata)
