"""Stories: the dataclass, the structure capability and its conformance check."""

import numpy as np
import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core import testing
from cphysfno_core.plugin import Stories


def test_stacked_stories_chain_the_floors_bottom_up():
    stories = Stories.stacked([5.49, 3.96, 3.96])
    assert stories.lower == (None, 0, 1)
    assert stories.upper == (0, 1, 2)
    assert stories.heights_m == (5.49, 3.96, 3.96)
    assert stories.n_stories == 3 and stories.floors == (0, 1, 2)
    assert stories.names == ("story-1", "story-2", "story-3")


def test_piers_over_the_ground_are_stories_too():
    stories = Stories((None, None), (np.int64(1), 0), (6.3, 8.1))
    assert stories.upper == (1, 0) and type(stories.upper[0]) is int
    assert stories.floors == (0, 1)


def test_drifts_and_the_first_sample_past_a_drift_ratio_by_hand():
    stories = Stories.stacked([4.0, 2.0])
    # two records, three samples, two floors (m)
    u = np.array(
        [
            [[0.0, 0.0], [0.1, 0.15], [0.3, 0.32]],  # story 1: 0.025, 0.075; story 2: 0.025, 0.01
            [[0.0, 0.0], [-0.1, -0.3], [0.0, 0.0]],  # story 2 drifts -0.2 m: ratio 0.1 at 1
        ]
    )
    np.testing.assert_allclose(stories.drifts(u)[0, :, 1], [0.0, 0.05, 0.02])
    np.testing.assert_allclose(stories.drifts(u)[1, 1], [-0.1, -0.2])
    assert stories.first_past(u, 0.05).tolist() == [2, 1]
    assert stories.first_past(u, 0.09).tolist() == [-1, 1]
    assert stories.first_past(u, 0.1).tolist() == [-1, -1]


@pytest.mark.parametrize(
    ("lower", "upper", "heights", "message"),
    [
        ((None,), (0, 1), (3.0, 3.0), "one entry per story"),
        ((), (), (), "at least one story"),
        ((None,), (-1,), (3.0,), ">= 0"),
        ((None,), (0.5,), (3.0,), "integers"),
        ((None,), (True,), (3.0,), "integers"),
        ((0,), (0,), (3.0,), "both ends"),
        ((None,), (0,), (0.0,), "finite and > 0"),
        ((None,), (0,), (float("inf"),), "finite and > 0"),
        ((None,), (0,), ("tall",), "numbers of m"),
    ],
)
def test_malformed_stories_are_refused(lower, upper, heights, message):
    with pytest.raises(cp.InputError, match=message):
        Stories(lower, upper, heights)


def test_a_structure_without_stories_says_so():
    structure = toy_components.ToyStructure()
    assert "stories" not in structure.capabilities
    with pytest.raises(cp.CapabilityError, match="to provide stories"):
        structure.stories()


def test_a_storied_structure_conforms():
    structure = toy_components.StoriedToyStructure()
    assert structure.stories() == Stories((None, 0), (0, 1), (3.0, 2.5))
    testing.check_structure(structure)


class StoriesPastTheOutputs(toy_components.StoriedToyStructure):
    name = "stories-past-the-outputs"

    def stories(self):
        return Stories.stacked([3.0, 3.0, 3.0])


class StoriesUndeclared(toy_components.ToyStructure):
    name = "stories-undeclared"

    def stories(self):
        return Stories.stacked([3.0, 3.0])


class StoriesAsTuple(toy_components.StoriedToyStructure):
    name = "stories-as-tuple"

    def stories(self):
        return ((None, 0), (0, 1), (3.0, 3.0))


class StoriesDeclaredOnly(toy_components.ToyStructure):
    name = "stories-declared-only"
    capabilities = frozenset({"stories"})


@pytest.mark.parametrize(
    ("structure", "message"),
    [
        (StoriesPastTheOutputs(), r"name outputs \[2\], but there are 2 outputs"),
        (StoriesUndeclared(), "defines stories\\(\\) but does not declare 'stories'"),
        (StoriesAsTuple(), "must return cphysfno_core.Stories"),
        (StoriesDeclaredOnly(), "declares 'stories' but does not define stories\\(\\)"),
    ],
    ids=lambda v: getattr(v, "name", ""),
)
def test_the_check_catches_broken_stories(structure, message):
    with pytest.raises(AssertionError, match=message):
        testing.check_structure(structure)


def test_a_story_without_height_has_its_drift_but_no_ratio():
    stories = Stories((None, 0), (0, 1), (float("nan"), 3.0))
    assert not stories.has_heights and stories.without_height() == ("story-1",)
    assert Stories.stacked([3.0, 3.0]).has_heights
    u = np.zeros((1, 3, 2))
    u[0, 1] = [0.5, 0.8]  # story 1 drifts 0.5 m, story 2 0.3 m (a ratio of 0.1)
    assert stories.first_past(u, 0.09).tolist() == [1]  # story 2 only: story 1 has no ratio
    assert stories.first_past(u, 0.2).tolist() == [-1]
