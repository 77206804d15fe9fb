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

    def hysteretic_bound(self, n_stories: int) -> np.ndarray:
        """``[d]`` the largest magnitude (m) of the hysteretic part ``z`` of ``F = k [alpha v
        + (1 - alpha) z]``: the yield drift."""
        return self.yield_drift(n_stories)

    def strength_lost_drift(self, n_stories: int) -> np.ndarray:
        """``[d]`` where ``alpha < 0``, the drift ``z_max (1 - 1 / alpha)`` (m) past which
        ``alpha v + (1 - alpha) z`` cannot stay of the drift's sign whatever the history;
        ``inf`` elsewhere."""
        alpha = per_story(self.params.alpha, n_stories, "story_law.alpha")
        softening = alpha < 0.0
        lost = np.full(n_stories, np.inf)
        bound = self.hysteretic_bound(n_stories)
        lost[softening] = bound[softening] * (1.0 - 1.0 / alpha[softening])
        return lost
