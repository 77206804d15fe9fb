"""Demand samples for the loss assessment tool pelicun 3 (FEMA P-58).

:func:`write_pelicun_demands` writes the EDPs that pelicun has a demand type for (peak and
residual story drift ratios, peak floor accelerations and velocities, and named responses
given one, such as an isolator's deformation ``BRD`` or a base shear) as the CSV file that
pelicun's ``DemandModel.load_sample`` reads::

    from cphysfno_core import edp
    from cphysfno_core.reporting.demands import write_pelicun_demands

    demands = edp.compute(responses, structure, motions)
    written = write_pelicun_demands("demands.csv", demands, collapsed=collapsed)

    from pelicun.assessment import Assessment

    assessment = Assessment({"PrintLog": False})
    assessment.demand.load_sample(str(written.path))  # a str: pelicun rejects a Path

pelicun is an optional dependency (the ``dev`` extra); this module writes the file
without it.

**The file pelicun reads** (pelicun 3.10; paths inside the ``pelicun`` package):

- ``model/demand_model.py``, ``DemandModel.load_sample(filepath)`` calls
  ``file_io.load_data(filepath, unit_conversion_factors, return_units=True)``;
  ``file_io.load_from_file`` reads it with ``pandas.read_csv(header=0, index_col=0)``.
  The path must be a ``str`` (``load_data`` raises ``TypeError`` for a ``Path``) and must
  end in ``.csv`` (``load_from_file`` raises ``ValueError`` otherwise).
- The first column is a row label. The row labelled ``Units`` (any case) holds each
  column's unit; ``load_data`` removes it and multiplies each column by that unit's factor
  from ``settings/default_units.json`` (``base.parse_units``). A unit missing from that
  table is taken as factor 1 without a warning (``unit_conversion_factors.get(unit,
  1.00)``), so the unit names must be exactly the table's. The other rows are the
  realisations; their labels are dropped (the sample is renumbered 0, 1, ...).
- Column labels are split on ``-`` (``base.convert_to_MultiIndex``); ``parse_header`` in
  ``load_sample`` takes four parts as ``event-type-location-direction`` and drops the
  event (the same docstring says that part will be required in a later version), three
  parts as ``type-location-direction``. This module writes the event ``1``, as pelicun's
  own ``examples/001/demands_s4.csv`` does: ``1-PID-1-1``.
- Demand types are the acronyms of ``EDP_TYPES`` in ``dlml/vocabulary.py`` (the
  ``simcenter-dlml`` package pelicun depends on): ``PID`` (story drift ratio, unit type
  unitless), ``RID`` (residual interstory drift ratio, unitless), ``PFA`` (peak floor
  acceleration, acceleration), ``PFV`` (peak floor velocity, speed), ``BRD`` (peak bearing
  deformation, displacement). ``load_sample`` itself reads any type name: a base shear
  written as ``VB`` in ``kN`` loads, in N inside pelicun. The acceleration units of
  ``default_units.json`` are
  ``mps2`` (1, the base unit), ``inps2``/``inchps2`` (0.0254), ``ftps2`` (0.3048) and
  ``g`` (9.80665); ``unitless`` and ``rad`` both have factor 1, and pelicun labels drift
  ratios ``unitless`` when it assigns units itself (``assessment._add_units``).
- Inside pelicun the sample is in base units (PFA in m/s^2); ``DemandModel.save_sample``
  and ``DemandModel.user_units`` give it back in the file's units.
- Locations: the damage model asks a component at location ``L`` for demand
  ``TYPE-(L + offset)-DIR`` (``_get_required_demand_type`` in ``model/demand_model.py``),
  with ``offset`` its fragility's ``Demand/Offset`` plus the option ``DemandOffset``,
  by default ``{"PFA": -1, "PFV": -1}`` (``settings/default_config.json``). So
  ``PID-L`` is the drift of story ``L`` (1 = the first story), ``PFA-0`` the ground and
  ``PFA-k`` floor level ``k`` at the top of story ``k``: a component in story ``L`` reads
  the acceleration of the floor it stands on, ``PFA-(L-1)``, unless its fragility adds
  +1. ``RID-L`` is per story like ``PID-L`` (``DemandModel.estimate_RID`` writes RID at
  the PID's locations; ``DLCalculationAssessment.calculate_asset`` puts its
  ``excessiveRID`` component at every RID location).
- A column ``ERROR`` marks realisations to leave out: ``load_sample`` drops every row
  whose ``ERROR`` value is nonzero and logs "Based on the values in the ERROR column, N
  demand samples were removed".

**Collapse.** pelicun has no collapse value in a demand sample: a demand sample holds
the realisations of the structure that stands, and the probability of collapse enters
through a collapse fragility, the ``collapse`` component of the damage model
(``Assessment.calculate_damage(collapse_fragility_configuration=...)``, or
``DL/Damage/CollapseFragility`` with ``DemandType``, ``CapacityMedian`` and ``Theta_1``
in a ``DL_calculation`` configuration). The one place pelicun recognises collapsed
realisations in demands is ``DLCalculationAssessment.calculate_demand``: the option
``DL/Demands/CollapseLimits`` (``{"PID": 0.06}`` in ``examples/001/input.json``) removes
every realisation whose largest demand of that type exceeds the limit, before the demand
distribution is fitted. A collapsed record written with a very large drift would therefore
be kept as a real demand by ``load_sample`` (only that option removes it), and one written
with NaN is kept too and makes the calibration fail (with a lognormal fit: "Conversion to
standard normal space was unsuccessful").

So a collapsed record is written with ``ERROR`` = 1 (``collapsed_rows="error"``, the
default): every record stays in the file, and pelicun leaves the collapsed ones out of
its sample whichever way it is run (its library API or ``DL_calculation``, with or
without collapse limits). ``collapsed_rows="omit"`` leaves them out of the file instead,
for readers that know no ``ERROR`` column. Either way the collapse fraction is returned
(:attr:`PelicunDemands.collapse_fraction`), for the collapse fragility given to pelicun
(:func:`cphysfno_core.reporting.fragility.fit_lognormal` fits one over the intensities of
many records).
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from ..signals import ResponseChannel
from ..signals.errors import InputError
from .edp import EDPs
from .edp_table import EDP_TABLE, definition

STANDARD_GRAVITY = 9.80665
"""m/s^2 per g: the factor of unit ``g`` in pelicun's ``settings/default_units.json``."""

EVENT = "1"
"""The event part of the column labels (``1-PID-1-1``); pelicun drops it when it reads."""

DIRECTION = "1"
"""The direction part of the column labels: every demand is written in direction 1."""

PFA_UNITS = {"g": STANDARD_GRAVITY, "mps2": 1.0}
"""The units :func:`write_pelicun_demands` writes peak floor accelerations in, by
pelicun's name, each with the m/s^2 in one of it."""

DRIFT_UNIT = "unitless"
"""pelicun's unit of drift ratios (``rad`` has the same factor, 1)."""

ERROR_COLUMN = f"{EVENT}-ERROR--"
"""The column that marks collapsed records (1) for pelicun to leave out."""


@dataclass(frozen=True)
class PelicunDemands:
    """What :func:`write_pelicun_demands` wrote.

    Attributes:
        path: the CSV file.
        n_records: records handed in.
        n_collapsed: collapsed ones among them (0 when none were marked).
        columns: the demand columns' labels, in the file's order (``1-PID-1-1``, ...,
            without ``ERROR``).
        units: the unit of each of ``columns``, pelicun's name for it.
    """

    path: Path
    n_records: int
    n_collapsed: int
    columns: tuple[str, ...]
    units: tuple[str, ...]

    @property
    def n_sampled(self) -> int:
        """Records in pelicun's demand sample once it has read the file: those that stood."""
        return self.n_records - self.n_collapsed

    @property
    def collapse_fraction(self) -> float:
        """Collapsed records over all records."""
        return self.n_collapsed / self.n_records


PELICUN_UNITS = frozenset(
    {"m", "mm", "cm", "km", "in", "inch", "ft", "mps", "cmps", "inps", "inchps", "ftps",
     "mps2", "inps2", "inchps2", "ftps2", "g", "N", "kN", "lbf", "kip", "kips",
     "Pa", "kPa", "MPa", "GPa", "psi", "ksi", "unitless", "rad"}
)  # fmt: skip
"""The unit names of pelicun's ``settings/default_units.json`` a demand may be written in
(pelicun takes any other name as factor 1 without a warning)."""

PFV_UNIT = "mps"
"""pelicun's unit of the peak floor velocities written (m/s)."""


@dataclass(frozen=True)
class _Block:
    """The columns of one demand type: its pelicun type, ``[n, k]`` values in the file's
    units, their locations and units."""

    name: str
    values: np.ndarray
    places: tuple[int, ...]
    units: tuple[str, ...]


def write_pelicun_demands(
    path: str | os.PathLike[str],
    demands: EDPs,
    collapsed: np.ndarray | None = None,
    *,
    pfa_unit: Literal["g", "mps2"] = "g",
    collapsed_rows: Literal["error", "omit"] = "error",
    non_converged: np.ndarray | None = None,
    include: tuple[str, ...] | None = None,
) -> PelicunDemands:
    """Write engineering demand parameters as a pelicun 3 demand sample (CSV).

    The file has a header row, a ``Units`` row, and one row per record labelled with the
    record's index in the arrays. Its columns come from the EDPs that have a pelicun
    demand type (:data:`~cphysfno_core.edp.EDP_TABLE`): ``1-PID-s-1`` and ``1-RID-s-1``
    for stories ``s = 1 .. n_stories`` (``unitless``), ``1-PFA-k-1`` for floor levels
    ``k = 0 .. n_floors`` (0 the ground) in ``pfa_unit``, ``1-PFV-k-1`` likewise in
    ``mps``, and the peak of each named response that has a ``pelicun_type``
    (``1-BRD-1-1`` for an isolator's deformation, say) at its ``pelicun_location`` in its
    unit, which must be one of pelicun's (:data:`PELICUN_UNITS`). With ``collapsed`` (or
    ``non_converged``) and ``collapsed_rows="error"`` a column ``1-ERROR--`` follows (1 for
    a collapsed record, 2 for one whose analysis did not converge below the collapse, else
    0; pelicun leaves out every nonzero one). Values are written with Python's shortest
    round-trip ``repr``; a collapsed record's values that are not finite are left empty.
    The file replaces ``path`` in one step. See the module's documentation for how
    pelicun reads it, and why collapse is written so.

    A building whose outputs include a level no story ends at (an isolation level under a
    superstructure whose stories start there, say) has more floors than stories: floor
    location ``k`` is its ``k``-th floor bottom up.

    Args:
        path: the CSV file to write; it must end in ``.csv`` (pelicun reads no other).
        demands: the records' EDPs (:func:`cphysfno_core.edp.compute`), drift ratios for
            stories with heights.
        collapsed: ``[n_records]`` booleans, True for a record whose structure collapsed;
            None when none did (no ``ERROR`` column is written).
        pfa_unit: ``"g"`` (the default, the unit of the FEMA P-58 fragilities: the values
            are divided by 9.80665) or ``"mps2"`` (m/s^2 as given). pelicun converts
            either to m/s^2 when it reads the file.
        collapsed_rows: ``"error"`` (the default) writes collapsed records with
            ``ERROR`` = 1 (non-converged ones with 2), which pelicun's ``load_sample``
            drops; ``"omit"`` leaves them out of the file (the remaining rows keep their
            record indices).
        non_converged: ``[n_records]`` booleans, True for a record whose analysis stopped
            converging below the collapse (a numerical failure, not a collapse: not in the
            collapse fraction); None when none did.
        include: the EDPs to write, by name (default: every one ``demands`` holds that
            pelicun has a type for).

    Returns:
        What was written, with the number of collapsed records.

    Raises:
        InputError: ``collapsed`` is not boolean or has the wrong shape, a record that did
            not collapse has a NaN or infinite value, a value is negative, there are no
            records or every record collapsed (pelicun then has no demand to sample: give
            it the collapse through its collapse fragility), a named response's unit is not
            pelicun's, or ``path``, ``pfa_unit``, ``collapsed_rows`` or ``include`` is not
            one pelicun reads.
    """
    path = Path(path)
    if path.suffix != ".csv":
        raise InputError(
            f"pelicun demand sample: {path} must end in .csv, the only file type pelicun's "
            "load_sample reads"
        )
    if pfa_unit not in PFA_UNITS:
        raise InputError(
            f"pelicun demand sample: pfa_unit={pfa_unit!r} is not one of {sorted(PFA_UNITS)}"
        )
    if collapsed_rows not in ("error", "omit"):
        raise InputError(
            f"pelicun demand sample: collapsed_rows={collapsed_rows!r} is neither 'error' "
            "nor 'omit'"
        )
    blocks = _blocks(demands, pfa_unit, include)
    n_records = demands.n_records
    if n_records == 0 or not blocks:
        raise InputError(
            f"pelicun demand sample: {n_records} records and {len(blocks)} demand types; it "
            "needs at least one record and one demand"
        )
    fell = _flags(collapsed, n_records, "collapsed")
    stopped = _flags(non_converged, n_records, "non_converged")
    error = np.where(fell, 1, np.where(stopped, 2, 0))

    for block in blocks:
        _check_values(block.name.lower(), block.values, error > 0)
    n_collapsed = int(fell.sum())
    if (error > 0).all():
        raise InputError(
            f"pelicun demand sample: all {n_records} records collapsed (or did not "
            "converge), so there is no "
            "demand of a standing structure for pelicun to sample: give pelicun the "
            "collapse through its collapse fragility (collapse fraction 1) instead"
        )

    columns = [f"{EVENT}-{b.name}-{place}-{DIRECTION}" for b in blocks for place in b.places]
    units = [unit for b in blocks for unit in b.units]
    table = np.concatenate([b.values for b in blocks], axis=1)
    flag = (collapsed is not None or non_converged is not None) and collapsed_rows == "error"
    rows = [r for r in range(n_records) if collapsed_rows == "error" or not error[r]]

    temporary = path.with_name(f".{path.name}.tmp")
    try:
        with open(temporary, "w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle, lineterminator="\n")
            writer.writerow(["", *columns, *([ERROR_COLUMN] if flag else [])])
            writer.writerow(["Units", *units, *([""] if flag else [])])
            for r in rows:
                cells = [repr(float(v)) if np.isfinite(v) else "" for v in table[r]]
                writer.writerow([str(r), *cells, *([str(int(error[r]))] if flag else [])])
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return PelicunDemands(path, n_records, n_collapsed, tuple(columns), tuple(units))


def _blocks(demands: EDPs, pfa_unit: str, include: tuple[str, ...] | None) -> list[_Block]:
    """The demand types to write, in :data:`EDP_TABLE` order, in the file's units."""
    if include is not None:
        unknown = [name for name in include if definition(name).name not in demands.values]
        if unknown:
            raise InputError(
                f"pelicun demand sample: include names {', '.join(unknown)}, which these "
                f"demands do not hold (they hold {', '.join(demands.values)})"
            )
        wanted = {definition(name).name for name in include}
    else:
        wanted = set(demands.values)
    blocks = []
    for key, what in EDP_TABLE.items():
        if key not in wanted or key not in demands.values:
            continue
        values = demands.values[key]
        n = values.shape[1]
        if what.axis == "story" and what.pelicun_type is not None:
            _check_ratios(key, demands)
            places = tuple(range(1, n + 1))
            blocks.append(_Block(what.pelicun_type, values, places, (DRIFT_UNIT,) * n))
        elif key == "PFA":
            per_unit = PFA_UNITS[pfa_unit]
            blocks.append(_Block("PFA", values / per_unit, tuple(range(n)), (pfa_unit,) * n))
        elif key == "PFV":
            blocks.append(_Block("PFV", values, tuple(range(n)), (PFV_UNIT,) * n))
        elif what.axis == "response":
            blocks += _response_blocks(values, demands.channels)
    return blocks


def _check_ratios(key: str, demands: EDPs) -> None:
    """Raise unless every story of the drift EDP ``key`` is a ratio (has a height)."""
    missing = [
        name
        for name, unit in zip(demands.columns[key], demands.units[key], strict=True)
        if unit != "m/m"
    ]
    if missing:
        raise InputError(
            f"pelicun demand sample: {', '.join(missing)} has no height, so its {key} is a "
            "drift in m, not the ratio pelicun's fragilities need: give the structure "
            "story_heights or drift_pairs, or leave it out with include"
        )


def _response_blocks(values: np.ndarray, channels: tuple[ResponseChannel, ...]) -> list[_Block]:
    """One block per named response that has a pelicun type."""
    found = []
    for j, channel in enumerate(channels):
        if channel.pelicun_type is None:
            continue
        if channel.unit not in PELICUN_UNITS:
            raise InputError(
                f"pelicun demand sample: named response '{channel.name}' is in "
                f"'{channel.unit}', which pelicun does not know (it would read it as factor "
                f"1): give its unit as one of {', '.join(sorted(PELICUN_UNITS))}"
            )
        found.append(
            _Block(
                channel.pelicun_type,
                values[:, j : j + 1],
                (channel.pelicun_location,),
                (channel.unit,),
            )
        )
    return found


def _flags(flags: np.ndarray | None, n_records: int, name: str) -> np.ndarray:
    if flags is None:
        return np.zeros(n_records, dtype=bool)
    found = np.asarray(flags)
    if found.dtype != np.bool_:
        raise InputError(
            f"pelicun demand sample: {name} has dtype {found.dtype}; it must be boolean, "
            "True for a record that is so"
        )
    if found.shape != (n_records,):
        raise InputError(
            f"pelicun demand sample: {name} has shape {found.shape}; it must be "
            f"({n_records},), one value per record"
        )
    return found


def _check_values(name: str, values: np.ndarray, fell: np.ndarray) -> None:
    bad = ~np.isfinite(values[~fell])
    if bad.any():
        record = int(np.flatnonzero(~fell)[np.flatnonzero(bad.any(axis=1))[0]])
        raise InputError(
            f"pelicun demand sample: {name} of record {record} is not finite "
            f"({values[record].tolist()}), and the record is not marked collapsed: mark it "
            "in `collapsed` or leave it out"
        )
    negative = np.isfinite(values) & (values < 0)
    if negative.any():
        record, column = (int(i) for i in np.argwhere(negative)[0])
        raise InputError(
            f"pelicun demand sample: {name} of record {record} is negative "
            f"({float(values[record, column])!r} in column {column}); peak and residual drift "
            "ratios and peak accelerations are magnitudes, >= 0"
        )
