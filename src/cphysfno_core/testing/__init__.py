"""Conformance checks for every component kind: call them from a plugin's tests."""

from .conformance import (
    check_ground_motion_source,
    check_operator,
    check_preprocessor,
    check_refiner,
    check_structure,
    small_motions,
)
from .story_law import check_story_law

__all__ = [
    "check_ground_motion_source",
    "check_operator",
    "check_preprocessor",
    "check_refiner",
    "check_story_law",
    "check_structure",
    "small_motions",
]
