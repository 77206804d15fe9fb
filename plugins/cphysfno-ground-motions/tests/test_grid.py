"""One time grid for records of various steps and lengths: anti-aliased resampling,
truncation and padding, and the messages for what cannot be put on the grid."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_core import DatasetError, InputError

from cphysfno_ground_motions import GroundMotionWarning, Record
from cphysfno_ground_motions.grid import common_grid, fit_length, resample


def _sine(frequency, dt, duration=10.0):
    t = np.arange(int(round(duration / dt)) + 1) * dt
    return np.sin(2 * np.pi * frequency * t)


def test_downsampling_keeps_content_below_the_new_nyquist_and_removes_content_above():
    old_dt, new_dt = 0.005, 0.02  # Nyquist 100 Hz -> 25 Hz
    kept = resample(_sine(8.0, old_dt), old_dt, new_dt)
    removed = resample(_sine(60.0, old_dt), old_dt, new_dt)  # would fold onto 10 Hz
    assert kept.size == removed.size == 501  # 10 s
    t = np.arange(kept.size) * new_dt
    interior = slice(50, -50)
    np.testing.assert_allclose(kept[interior], np.sin(2 * np.pi * 8.0 * t)[interior], atol=0.01)
    assert np.abs(removed[interior]).max() < 0.01


def test_upsampling_by_a_rational_factor_interpolates_band_limited():
    old_dt, new_dt = 0.0024, 0.005
    out = resample(_sine(3.0, old_dt, duration=12.0), old_dt, new_dt)
    t = np.arange(out.size) * new_dt
    np.testing.assert_allclose(out[100:-100], np.sin(2 * np.pi * 3.0 * t)[100:-100], atol=0.01)
    fine = resample(_sine(3.0, 0.01), 0.01, 0.0025)
    assert fine.size == 4001 and abs(fine[4 * 123] - _sine(3.0, 0.01)[123]) < 0.01


def test_a_step_without_a_small_rational_ratio_is_refused():
    with pytest.raises(InputError, match="not a fraction of integers"):
        resample(np.zeros(100), 0.01, 0.01 / np.pi)


def test_records_are_cut_or_zero_padded():
    record = np.arange(1.0, 6.0)
    np.testing.assert_array_equal(fit_length(record, 3), [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(fit_length(record, 7), [1, 2, 3, 4, 5, 0, 0])


def _record(name, dt, duration, value=1.0):
    steps = int(round(duration / dt)) + 1
    return Record(np.full(steps, value), dt, {"name": name})


def test_fixed_duration_cuts_long_records_and_pads_short_ones_with_a_warning():
    records = [_record("long", 0.005, 30.0), _record("short", 0.005, 12.0)]
    with pytest.warns(GroundMotionWarning, match=r"1 records zero-padded to 20 s: short \(12"):
        motions = common_grid(
            records, dt=0.005, resample_all=True, duration=20.0, pad_short=True, where="set"
        )
    assert motions.acceleration.shape == (2, 4001)
    assert motions.acceleration[1, 2400] == 1.0 and motions.acceleration[1, 2401] == 0.0
    assert motions.metadata[1]["native_duration"] == pytest.approx(12.0)
    with pytest.warns(GroundMotionWarning, match="left out as shorter than 20 s: short"):
        motions = common_grid(
            records, dt=0.005, resample_all=True, duration=20.0, pad_short=False, where="set"
        )
    assert [m["name"] for m in motions.metadata] == ["long"]


def test_no_record_long_enough_without_padding_is_an_error():
    with pytest.raises(DatasetError, match="no record of set lasts 20 s"):
        common_grid(
            [_record("a", 0.01, 5.0)],
            dt=None,
            resample_all=True,
            duration=20.0,
            pad_short=False,
            where="set",
        )


def test_mixed_steps_without_resampling_name_the_records():
    records = [_record("a", 0.01, 5.0), _record("b", 0.005, 5.0), _record("c", 0.01, 5.0)]
    with pytest.raises(DatasetError, match=r"mixes time steps \(0.005 s: b; 0.01 s: a, c\)"):
        common_grid(records, dt=None, resample_all=False, duration=None, pad_short=True, where="s")
    with pytest.warns(GroundMotionWarning, match="1 records left out because their dt is not"):
        motions = common_grid(
            records, dt=0.01, resample_all=False, duration=None, pad_short=True, where="s"
        )
    assert [m["name"] for m in motions.metadata] == ["a", "c"]
    with pytest.raises(DatasetError, match="no record of s has dt = 0.02 s"):
        common_grid(records, dt=0.02, resample_all=False, duration=None, pad_short=True, where="s")


def test_native_grid_is_the_finest_step_and_the_longest_record():
    records = [_record("a", 0.01, 5.0, 2.0), _record("b", 0.005, 3.0)]
    motions = common_grid(
        records, dt=None, resample_all=True, duration=None, pad_short=True, where="s"
    )
    assert motions.dt == 0.005 and motions.n_steps == 1001  # 5 s
    assert motions.metadata[0]["native_dt"] == 0.01
    assert abs(motions.acceleration[0, 500] - 2.0) < 0.02  # band-limited interpolation


def test_a_cut_that_leaves_out_most_of_a_records_shaking_warns_naming_it():
    """A record that is quiet for 25 s and shakes after keeps none of its Arias intensity
    within 20 s (scaled to a target it would be amplified noise): the cut names it and
    how to start at the shaking; a record that shakes within the grid is not named."""
    quiet = np.concatenate([np.full(2501, 1e-4), np.ones(1000)])
    records = [Record(quiet, 0.01, {"name": "late"}), _record("early", 0.01, 35.0)]
    with pytest.warns(GroundMotionWarning) as caught:
        common_grid(records, dt=0.01, resample_all=True, duration=20.0, pad_short=True, where="s")
    (message,) = [str(w.message) for w in caught]
    assert "s: 1 records keep less than 50% of their shaking (Arias intensity) within 20 s" in (
        message
    )
    assert "late (0%)" in message and "early" not in message and "pre_shaking" in message
