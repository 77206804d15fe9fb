"""Any AT2 text either reads into a finite record or is refused with the package's own
error naming the file."""

import numpy as np
from cphysfno_core import DatasetError
from cphysfno_core.signals.at2 import read_at2
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

HEADER = (
    "PEER NGA STRONG MOTION DATABASE RECORD\nEvent, 1/1/2000, Station, 090\n"
    "ACCELERATION TIME SERIES IN UNITS OF G\n"
)
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(lambda x: f"{x:.4E}"),
    st.integers(-5, 5).map(str),
    st.sampled_from(["", "abc", "1e400", "--1"]),
)
npts_lines = st.one_of(
    st.builds(lambda n, dt: f"NPTS= {n}, DT= {dt} SEC", st.integers(-3, 12), numbers),
    st.builds(lambda n, dt: f"{n}    {dt}    NPTS, DT", st.integers(0, 12), numbers),
    st.text(max_size=30),
)
bodies = st.lists(st.lists(numbers, max_size=6).map("  ".join), max_size=4).map("\n".join)


@given(header=st.one_of(st.just(HEADER), st.text(max_size=80)), npts=npts_lines, body=bodies)
@settings(
    max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
def test_any_at2_text_reads_or_is_refused_by_name(tmp_path, header, npts, body):
    path = tmp_path / "record.AT2"
    path.write_text(header + npts + "\n" + body)
    try:
        record = read_at2(path)
    except DatasetError as error:
        assert str(path) in str(error)
        return
    assert np.isfinite(record.acceleration).all()
