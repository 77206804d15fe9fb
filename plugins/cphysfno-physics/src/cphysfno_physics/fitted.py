"""The check every preprocessor makes before it transforms."""

from __future__ import annotations

from cphysfno_core import NotFittedError
from cphysfno_core.plugin import PhysicsPreprocessor


def check_fitted(preprocessor: PhysicsPreprocessor, attribute: str) -> None:
    """Raise :class:`NotFittedError` unless ``fit`` has set ``attribute`` on ``preprocessor``."""
    if not hasattr(preprocessor, attribute):
        raise NotFittedError(
            f"preprocessor '{preprocessor.name}' is not fitted: call fit(structure) "
            "before transform(motions)"
        )
