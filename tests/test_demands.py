"""Demand samples for pelicun: the file written, read back by pelicun 3.10 itself, and the
errors for input pelicun could not use."""

import sys
import warnings

import numpy as np
import pytest

from cphysfno_core import InputError, edp
from cphysfno_core.plugin import Stories
from cphysfno_core.reporting.demands import STANDARD_GRAVITY, write_pelicun_demands
from cphysfno_core.signals import ResponseChannel

# 3 records, 2 stories: drift ratios (m/m) and floor accelerations in m/s^2 (ground first).
PID = np.array([[0.010, 0.012], [0.020, 0.015], [0.015, 0.013]])
RID = np.array([[0.001, 0.002], [0.003, 0.001], [0.002, 0.0]])
PFA = np.array([[2.9, 4.9, 5.9], [3.4, 5.4, 6.9], [3.1, 5.1, 6.4]])
LABELS = [("PID", "1"), ("PID", "2"), ("RID", "1"), ("RID", "2")] + [
    ("PFA", str(k)) for k in range(3)
]
TWO_STORIES = Stories.stacked([3.0, 3.0])


def _demands(pid=PID, rid=RID, pfa=PFA, stories=TWO_STORIES, **more):
    """The EDPs of the three records (no RID where ``rid`` is None)."""
    tables = {"PID": pid, "RID": rid, "PFA": pfa} | more
    return edp.EDPs.from_tables({k: v for k, v in tables.items() if v is not None}, stories)


@pytest.fixture(scope="module")
def assessment():
    """A fresh pelicun ``Assessment`` per call. Importing pelicun wraps ``sys.stdout`` and
    ``sys.stderr`` (colorama), replaces ``warnings.showwarning`` and changes pandas' display
    options; all of that is put back, so the rest of the session is not affected."""
    pytest.importorskip("pelicun", minversion="3.10")
    import pandas as pd

    options = ["display.max_rows", "display.max_columns", "display.width"]
    saved = (sys.stdout, sys.stderr, warnings.showwarning, [pd.get_option(o) for o in options])
    try:
        from pelicun.assessment import Assessment
    finally:
        sys.stdout, sys.stderr, warnings.showwarning = saved[:3]
        for option, value in zip(options, saved[3], strict=True):
            pd.set_option(option, value)
    return lambda: Assessment({"PrintLog": False})


def _load(assessment, path):
    run = assessment()
    run.demand.load_sample(str(path))
    return run


def _column(frame, name, place):
    return frame[(name, place, "1")].to_numpy(dtype=float)


def test_the_file_has_pelicuns_header_and_units_rows(tmp_path):
    written = write_pelicun_demands(tmp_path / "demands.csv", _demands())
    lines = written.path.read_text().splitlines()
    assert lines[0] == (",1-PID-1-1,1-PID-2-1,1-RID-1-1,1-RID-2-1,1-PFA-0-1,1-PFA-1-1,1-PFA-2-1")
    assert lines[1] == "Units,unitless,unitless,unitless,unitless,g,g,g"
    assert [line.split(",")[0] for line in lines[2:]] == ["0", "1", "2"]
    assert float(lines[2].split(",")[5]) == 2.9 / STANDARD_GRAVITY
    assert written.units == ("unitless",) * 4 + ("g",) * 3
    assert (written.n_records, written.n_collapsed, written.n_sampled) == (3, 0, 3)


def test_pelicun_reads_the_values_and_units(tmp_path, assessment):
    written = write_pelicun_demands(tmp_path / "demands.csv", _demands())
    run = _load(assessment, written.path)
    sample = run.demand.sample
    assert sorted(sample.columns) == sorted((n, p, "1") for n, p in LABELS)
    assert run.demand.user_units[("PFA", "0", "1")] == "g"
    assert run.demand.user_units[("PID", "1", "1")] == "unitless"
    assert run.unit_conversion_factors["g"] == STANDARD_GRAVITY
    for s in range(2):
        np.testing.assert_array_equal(_column(sample, "PID", str(s + 1)), PID[:, s])
        np.testing.assert_array_equal(_column(sample, "RID", str(s + 1)), RID[:, s])
    reported = run.demand.save_sample()  # in the file's units: g
    for k in range(3):
        # pelicun holds m/s^2 inside and reports g, ours converted by hand
        np.testing.assert_allclose(_column(sample, "PFA", str(k)), PFA[:, k], rtol=1e-14)
        np.testing.assert_allclose(
            _column(reported, "PFA", str(k)), PFA[:, k] / 9.80665, rtol=1e-14
        )


def test_an_isolation_level_and_a_base_shear_are_demands_pelicun_reads(tmp_path, assessment):
    # two superstructure stories standing on an isolation level (output 0, no height):
    # ground, base, two floors; the isolator's deformation and the base shear recorded
    isolated = Stories((None, 0, 1), (0, 1, 2), (float("nan"), 3.0, 3.0))
    pfa = np.column_stack([PFA[:, 0], 0.4 * PFA[:, 0], PFA[:, 1:]])
    pfv = np.abs(pfa) * 0.1
    pid = np.column_stack([[0.21, 0.33, 0.27], PID])  # the isolator's drift in m, then ratios
    channels = (
        ResponseChannel("isolator", "m", pelicun_type="BRD"),
        ResponseChannel("base_shear", "kN", pelicun_type="VB", pelicun_location=0),
        ResponseChannel("axial", "kN"),  # no pelicun type: not written
    )
    peaks = np.array([[0.2, 310.0, 5.0], [0.3, 420.0, 6.0], [0.25, 365.0, 5.5]])
    demands = edp.EDPs.from_tables(
        {"PFA": pfa, "PFV": pfv, "PR": peaks}, isolated, channels=channels
    )
    assert demands.units["PR"] == ("m", "kN", "kN")
    written = write_pelicun_demands(tmp_path / "isolated.csv", demands)
    header = written.path.read_text().splitlines()[0].split(",")
    assert header[1:] == [
        *(f"1-PFA-{k}-1" for k in range(4)),
        *(f"1-PFV-{k}-1" for k in range(4)),
        "1-BRD-1-1",
        "1-VB-0-1",
    ]
    run = _load(assessment, written.path)
    sample = run.demand.sample
    for k in range(4):
        np.testing.assert_allclose(_column(sample, "PFA", str(k)), pfa[:, k], rtol=1e-14)
        np.testing.assert_allclose(_column(sample, "PFV", str(k)), pfv[:, k], rtol=1e-14)
    np.testing.assert_allclose(_column(sample, "BRD", "1"), peaks[:, 0], rtol=1e-14)
    np.testing.assert_allclose(sample[("VB", "0", "1")], 1000.0 * peaks[:, 1], rtol=1e-14)  # N
    assert run.demand.user_units[("VB", "0", "1")] == "kN"
    with_drifts = edp.EDPs.from_tables({"PID": pid, "PFA": pfa}, isolated)
    assert with_drifts.units["PID"] == ("m", "m/m", "m/m")
    with pytest.raises(InputError, match="story-1 has no height"):
        write_pelicun_demands(tmp_path / "drifts.csv", with_drifts)


def test_a_named_response_in_a_unit_pelicun_does_not_know_is_refused(tmp_path):
    channel = ResponseChannel("base_shear", "tonf", pelicun_type="VB")
    demands = edp.EDPs.from_tables({"PR": np.ones((3, 1))}, TWO_STORIES, channels=(channel,))
    with pytest.raises(InputError, match="'tonf', which pelicun does not know"):
        write_pelicun_demands(tmp_path / "d.csv", demands)


def test_accelerations_in_metres_per_second_squared(tmp_path, assessment):
    written = write_pelicun_demands(tmp_path / "demands.csv", _demands(rid=None), pfa_unit="mps2")
    run = _load(assessment, written.path)
    assert run.demand.user_units[("PFA", "2", "1")] == "mps2"
    assert "RID" not in run.demand.sample.columns.get_level_values("type")
    np.testing.assert_array_equal(_column(run.demand.sample, "PFA", "2"), PFA[:, 2])


def test_collapsed_records_are_flagged_and_pelicun_leaves_them_out(tmp_path, assessment):
    pid, rid, pfa = PID.copy(), RID.copy(), PFA.copy()
    pid[1], rid[1], pfa[1, 1:] = np.nan, np.nan, np.inf  # what a collapsed record may hold
    collapsed = np.array([False, True, False])
    written = write_pelicun_demands(tmp_path / "demands.csv", _demands(pid, rid, pfa), collapsed)
    assert (written.n_collapsed, written.n_sampled) == (1, 2)
    assert written.collapse_fraction == pytest.approx(1 / 3)
    lines = written.path.read_text().splitlines()
    assert lines[0].endswith(",1-ERROR--") and lines[1].endswith("g,")
    assert lines[3] == f"1,,,,,{float(pfa[1, 0] / STANDARD_GRAVITY)!r},,,1"
    assert lines[2].endswith(",0") and lines[4].endswith(",0")

    run = _load(assessment, written.path)
    sample = run.demand.sample
    assert len(sample) == 2 and "ERROR" not in sample.columns.get_level_values("type")
    np.testing.assert_array_equal(_column(sample, "PID", "1"), PID[[0, 2], 0])
    # the standing records are a sample pelicun can resample
    run.demand.calibrate_model({"ALL": {"DistributionFamily": "empirical"}})
    run.demand.generate_sample({"SampleSize": 4, "PreserveRawOrder": True})
    np.testing.assert_array_equal(
        _column(run.demand.save_sample(), "PID", "2"), PID[[0, 2, 0, 2], 1]
    )


def test_collapsed_records_can_be_left_out_of_the_file(tmp_path, assessment):
    collapsed = np.array([True, False, False])
    written = write_pelicun_demands(
        tmp_path / "demands.csv", _demands(), collapsed, collapsed_rows="omit"
    )
    lines = written.path.read_text().splitlines()
    assert "ERROR" not in lines[0] and [line.split(",")[0] for line in lines[2:]] == ["1", "2"]
    assert written.n_collapsed == 1
    run = _load(assessment, written.path)
    np.testing.assert_array_equal(_column(run.demand.sample, "RID", "2"), RID[1:, 1])


def test_no_collapse_writes_an_error_column_of_zeros_when_collapse_is_given(tmp_path):
    written = write_pelicun_demands(tmp_path / "d.csv", _demands(), np.zeros(3, bool))
    lines = written.path.read_text().splitlines()
    assert lines[0].endswith(",1-ERROR--") and all(line.endswith(",0") for line in lines[2:])


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"pfa": PFA[:, :1]}, "PFA has shape (3, 1); it must be [n_records, 3]: ground, "),
        ({"rid": RID[:2]}, "EDP tables of different numbers of records"),
    ],
)
def test_tables_that_do_not_fit_the_stories_are_refused(change, message):
    with pytest.raises(InputError) as raised:
        _demands(**change)
    assert message in str(raised.value)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"pid": PID[:0]}, "0 records"),
        ({"collapsed": np.array([0, 1, 0])}, "collapsed has dtype int64; it must be boolean"),
        ({"collapsed": np.array([False, True])}, "collapsed has shape (2,); it must be (3,)"),
        ({"collapsed": np.ones(3, bool)}, "all 3 records collapsed"),
        ({"pid": np.where([[0, 0], [0, 1], [0, 0]], np.nan, PID)}, "pid of record 1 is not finite"),
        ({"pfa": np.where([[0, 0, 0], [0, 0, 0], [1, 0, 0]], np.inf, PFA)}, "pfa of record 2"),
        ({"rid": -RID}, "rid of record 0 is negative (-0.001 in column 0)"),
        ({"pfa_unit": "m/s2"}, "pfa_unit='m/s2' is not one of ['g', 'mps2']"),
        ({"collapsed_rows": "drop"}, "collapsed_rows='drop' is neither"),
        ({"path": "demands.txt"}, "must end in .csv"),
        ({"include": ("PFV",)}, "include names PFV, which these demands do not hold"),
    ],
)
def test_input_pelicun_could_not_use_is_refused(tmp_path, change, message):
    tables = {k: change.pop(k) for k in ("pid", "rid", "pfa") if k in change}
    if "pid" in tables and len(tables["pid"]) == 0:
        tables |= {"rid": RID[:0], "pfa": PFA[:0]}
    arguments = {"path": "demands.csv", "demands": _demands(**tables)} | change
    arguments["path"] = tmp_path / arguments["path"]
    with pytest.raises(InputError) as raised:
        write_pelicun_demands(**arguments)
    assert message in str(raised.value)
    assert list(tmp_path.iterdir()) == []


def test_a_collapsed_record_may_hold_anything_but_negative_values(tmp_path):
    pid = PID.copy()
    pid[0, 0] = -0.5
    with pytest.raises(InputError, match="pid of record 0 is negative"):
        write_pelicun_demands(tmp_path / "d.csv", _demands(pid), np.array([True, False, False]))
