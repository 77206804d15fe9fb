"""What the laws with a yield drift share: the per-story ``[k, alpha, u_y]`` coefficients
and the yield drift the physics checks drive the stories past."""

from __future__ import annotations

import numpy as np
from cphysfno_core.plugin import StoryLaw, per_story


class YieldingLaw(StoryLaw):
    """A story law whose ``Params`` have ``alpha`` and ``yield_displacement`` (scalars or
    one value per story)."""

    def coefficients(self, stiffness: np.ndarray) -> np.ndarray:
        """``[d, 3]``: ``k`` (N/m), ``alpha``, ``u_y`` (m) of each story."""
        d = len(stiffness)
        return np.column_stack(
            [
                np.asarray(stiffness, dtype=np.float64),
                per_story(self.params.alpha, d, "story_law.alpha"),
                self.yield_drift(d),
            ]
        )

    def yield_drift(self, n_stories: int) -> np.ndarray:
        """``[d]`` the parameter ``yield_displacement`` of each story, m."""
        return per_story(self.params.yield_displacement, n_stories, "story_law.yield_displacement")
