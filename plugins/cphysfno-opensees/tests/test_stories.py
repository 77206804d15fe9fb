"""The frame's and the bridge's stories: which outputs bound each, and how tall it is."""

from __future__ import annotations

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core import edp


def test_the_frame_has_nine_stacked_stories_from_the_ground_to_the_roof():
    frame = cp.create("structure", "sac9-frame")
    stories = frame.stories()
    assert "stories" in frame.capabilities
    assert stories.lower == (None, 0, 1, 2, 3, 4, 5, 6, 7)
    assert stories.upper == tuple(range(9))
    np.testing.assert_allclose(stories.heights_m, [5.4864] + [3.9624] * 8)
    assert sum(stories.heights_m) == pytest.approx(37.19, abs=0.01)  # the paper's height
    stories.check_outputs(frame.n_outputs)
    assert [frame.output_names[i] for i in stories.upper[:2]] == ["level-2", "level-3"]


def test_each_bridge_column_is_a_story_over_its_bent_height():
    heights = (6.0, 7.0, 8.0, 9.0, 10.0)
    bridge = cp.create("structure", "auburn-ravine-bridge", pier_heights=heights)
    stories = bridge.stories()
    assert "stories" in bridge.capabilities
    assert stories.lower == (None,) * 10 and stories.upper == tuple(range(10))
    assert stories.heights_m == (6.0, 6.0, 7.0, 7.0, 8.0, 8.0, 9.0, 9.0, 10.0, 10.0)
    stories.check_outputs(bridge.n_outputs)
    # A column's drift ratio is its top's displacement over its own bent's height.
    t = np.arange(101) * 0.01
    motions = cp.GroundMotions(np.sin(2 * np.pi * t), 0.01)
    u = np.ones((1, 101, 10)) * np.sin(np.pi * t)[None, :, None] * 0.06
    found = edp.compute(u, bridge, motions)
    np.testing.assert_allclose(found.pid[0], 0.06 / np.repeat(heights, 2))
