"""PEER NGA-West2 AT2 reader: valid files in both header layouts, and malformed ones
refused with the file and line named."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_core import DatasetError

from cphysfno_ground_motions import read_at2

G = 9.80665
TITLE = "Imperial Valley-06, 10/15/1979, El Centro Array #6, 233"


def at2_text(values, dt=0.005, npts=None, units="ACCELERATION TIME SERIES IN UNITS OF G"):
    """An AT2 file in the NGA-West2 layout, five samples a line."""
    npts = len(values) if npts is None else npts
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        TITLE,
        units,
        f"NPTS=  {npts}, DT=   {dt:.4f} SEC",
    ]
    for start in range(0, len(values), 5):
        lines.append("".join(f"  {v: .7E}" for v in values[start : start + 5]))
    return "\n".join(lines) + "\n"


def test_reads_header_samples_and_converts_g(tmp_path):
    values = np.sin(np.arange(13) * 0.3) * 0.2
    path = tmp_path / "RSN181_IMPVALL.H_H-E06230.AT2"
    path.write_text(at2_text(values))
    record = read_at2(path)
    np.testing.assert_allclose(record.acceleration, values * G, rtol=1e-7)
    assert record.dt == pytest.approx(0.005)
    assert record.metadata["event"] == "Imperial Valley-06"
    assert record.metadata["date"] == "10/15/1979"
    assert record.metadata["station"] == "El Centro Array #6"
    assert record.metadata["component"] == "233"
    assert record.name == path.name and record.metadata["file"] == str(path)


def test_reads_the_older_header_and_run_together_numbers(tmp_path):
    path = tmp_path / "old.at2"
    path.write_text(
        "PEER STRONG MOTION DATABASE RECORD. PROCESSING BY PACIFIC ENGINEERING.\n"
        "IMPERIAL VALLEY 10/15/79 2316, EL CENTRO ARRAY #6, 230\n"
        "ACCELERATION TIME HISTORY IN UNITS OF G\n"
        "    4    .0100    NPTS, DT\n"
        " .1000E-01-.2000E-01  .3000E-01\n"
        "-.4000E-01\n"
    )
    record = read_at2(path)
    np.testing.assert_allclose(record.acceleration, np.array([0.01, -0.02, 0.03, -0.04]) * G)
    assert record.dt == pytest.approx(0.01)


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("PEER NGA\nonly two lines\n", 3, "header ends early"),
        (at2_text([0.1, 0.2], units="VELOCITY TIME SERIES IN UNITS OF CM/S"), 3, "units of g"),
        (at2_text([0.1, 0.2]).replace("NPTS=  2, DT=   0.0050 SEC", "POINTS 2"), 4, "NPTS"),
        (at2_text([0.1, 0.2], dt=0.0), 4, "DT must be > 0"),
        (at2_text([0.1, 0.2, 0.3]).replace("3.0000000E-01", "3.0x00E-01"), 5, "'3.0x00E-01'"),
        (at2_text([0.1, 0.2, 0.3], npts=5), 5, "ends after 3 samples but NPTS = 5"),
        (at2_text([0.1] * 7, npts=6), 6, "more samples than NPTS = 6"),
    ],
)
def test_malformed_files_are_refused_naming_file_and_line(tmp_path, text, line, message):
    path = tmp_path / "bad.AT2"
    path.write_text(text)
    with pytest.raises(DatasetError, match=message) as error:
        read_at2(path)
    assert f"{path}, line {line}:" in str(error.value)


def test_missing_file_names_the_file(tmp_path):
    with pytest.raises(DatasetError, match="nowhere.AT2"):
        read_at2(tmp_path / "nowhere.AT2")
