"""A script keyword that sets the nodes' elevations moves a family's story heights: each
record's drift ratios are over the heights of its own model."""

from __future__ import annotations

import numpy as np

import cphysfno_core as cp
from cphysfno_core.data.record_stories import RecordStories

SCRIPT = '''
import openseespy.opensees as ops


def build(h=3.0, k=2.0e4):
    """Two stories of elastic columns in kN and m, the first h m high, the second 3 m."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 0.0, h)
    ops.node(3, 0.0, h + 3.0)
    ops.fix(1, 1, 1, 1)
    ops.mass(2, 10.0, 10.0, 0.0)
    ops.mass(3, 10.0, 10.0, 0.0)
    ops.geomTransf("Linear", 1)
    ops.element("elasticBeamColumn", 1, 1, 2, 0.1, 2.0e8, k * 1.0e-5, 1)
    ops.element("elasticBeamColumn", 2, 2, 3, 0.1, 2.0e8, k * 1.0e-5, 1)
'''


def test_a_drawn_elevation_moves_the_heights_and_a_drawn_stiffness_does_not(tmp_path):
    path = tmp_path / "columns.py"
    path.write_text(SCRIPT)
    structure = cp.create(
        "structure", "opensees-model", script=str(path), outputs=[(2, 1), (3, 1)],
        arguments={"h": 3.0, "k": 2.0e4},
    )  # fmt: skip
    family = RecordStories(structure)
    assert family.stories.heights_m == (3.0, 3.0)
    assert family.heights({"arguments.k": np.array([1.5e4, 2.5e4])}, 2) is None
    found = family.heights(
        {"arguments.h": np.array([2.5, 4.0, 2.5]), "arguments.k": np.array([1.5e4, 2.5e4, 2e4])}, 3
    )
    np.testing.assert_allclose(found, [[2.5, 3.0], [4.0, 3.0], [2.5, 3.0]], rtol=1e-12)
