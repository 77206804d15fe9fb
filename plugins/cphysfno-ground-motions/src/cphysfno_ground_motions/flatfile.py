"""Reader of the NGA-West2 flatfile (CSV), or of the ``_SearchResults.csv`` that PEER's
ground-motion database gives with a download: what is known of each record, by RSN.

Columns are found by name, ignoring case, spaces and punctuation; the NGA-West2 names come
first among the accepted ones. Values of -999 (the flatfile's "unknown") and empty cells
read as missing. The table starts at the first row that names a record-sequence-number
column; where lines come above it (``_SearchResults.csv`` describes the search there), it
ends at the first empty row (where ``_SearchResults.csv`` begins its next table, of
spectra). PEER's scale factor is kept as ``peer_scale_factor``, not applied: the source's
own scaling settings decide the records' amplitude.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path
from typing import Any

from cphysfno_core import DatasetError

COLUMNS: dict[str, tuple[str, ...]] = {
    "rsn": ("Record Sequence Number", "RSN"),
    "magnitude": ("Earthquake Magnitude", "Magnitude", "Mag"),
    "rjb_km": ("Joyner-Boore Dist. (km)", "Rjb (km)", "Rjb"),
    "vs30": ("Vs30 (m/s) selected for analysis", "Vs30 (m/s)", "Vs30 (m/sec)", "Vs30"),
    "rrup_km": ("ClstD (km)", "Rrup (km)", "Rrup"),
    "event": ("Earthquake Name", "Event"),
    "year": ("YEAR",),
    "station": ("Station Name", "Station"),
    "mechanism": ("Mechanism Based on Rake Angle", "Mechanism"),
    "peer_scale_factor": ("Scale Factor",),
    "horizontal_1_file": ("Horizontal-1 Acc. Filename",),
    "horizontal_2_file": ("Horizontal-2 Acc. Filename",),
}
"""Metadata key -> accepted column names, in order of preference."""

NUMERIC = ("magnitude", "rjb_km", "vs30", "rrup_km", "peer_scale_factor")
MISSING = -999.0


def _key(name: str) -> str:
    return re.sub(r"[^a-z0-9]", "", name.lower())


def _number(text: str, path: Path, line: int, column: str) -> float | None:
    if not text.strip():
        return None
    try:
        value = float(text)
    except ValueError:
        raise DatasetError(
            f"{path}, line {line}: column {column!r} holds {text!r}, not a number"
        ) from None
    return None if value == MISSING else value


def read_flatfile(path: str | Path) -> dict[int, dict[str, Any]]:
    """Metadata of every row, keyed by record sequence number (RSN).

    Each row's mapping holds the keys of :data:`COLUMNS` whose column the file has
    (numbers as float, ``year`` and ``rsn`` as int, the rest as text); missing values are
    left out.

    Raises:
        DatasetError: the file cannot be read, has no RSN column (the message lists the
            columns it has), a number cell is not a number, or an RSN appears twice.
    """
    path = Path(path)
    try:
        with path.open(newline="", encoding="utf-8-sig", errors="replace") as handle:
            rows = list(csv.reader(handle))
    except OSError as error:
        raise DatasetError(f"{path}: cannot read the flatfile ({error.strerror})") from None
    if not rows:
        raise DatasetError(f"{path}: the flatfile is empty")
    rsn_names = {_key(name) for name in COLUMNS["rsn"]}
    start = next((i for i, row in enumerate(rows) if rsn_names & {_key(c) for c in row}), 0)
    end = None
    if start > 0:  # a search-results file: its table of records ends at an empty row
        blank = (i for i in range(start + 1, len(rows)) if not any(c.strip() for c in rows[i]))
        end = next(blank, None)
    offset, rows = start, rows[start:end]
    header = [_key(h) for h in rows[0]]
    where: dict[str, int] = {}
    for field, names in COLUMNS.items():
        for name in names:
            if _key(name) in header:
                where[field] = header.index(_key(name))
                break
    if "rsn" not in where:
        raise DatasetError(
            f"{path}: no record sequence number column ({' or '.join(COLUMNS['rsn'])}); "
            f"its columns are {', '.join(rows[0][:12])}{'...' if len(rows[0]) > 12 else ''}"
        )
    table: dict[int, dict[str, Any]] = {}
    first_line: dict[int, int] = {}
    for line, row in enumerate(rows[1:], start=offset + 2):
        if not any(cell.strip() for cell in row):
            continue
        cells = {field: row[i] if i < len(row) else "" for field, i in where.items()}
        rsn_value = _number(cells.pop("rsn"), path, line, rows[0][where["rsn"]])
        if rsn_value is None:
            raise DatasetError(f"{path}, line {line}: the record sequence number is missing")
        rsn = int(rsn_value)
        if rsn in first_line:
            raise DatasetError(
                f"{path}, line {line}: RSN {rsn} appears again (first on line {first_line[rsn]})"
            )
        first_line[rsn] = line
        entry: dict[str, Any] = {"rsn": rsn}
        for field, text in cells.items():
            if field in NUMERIC or field == "year":
                value = _number(text, path, line, rows[0][where[field]])
                if value is not None:
                    entry[field] = int(value) if field == "year" else value
            elif text.strip() and text.strip() != str(int(MISSING)):
                entry[field] = text.strip()
        table[rsn] = entry
    return table
