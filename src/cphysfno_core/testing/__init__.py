"""Conformance checks for every component kind: call them from a plugin's tests.

Each check raises ``AssertionError`` with a message naming the component and the broken
promise, and returns nothing when the component conforms. ``check_<kind>`` runs every
check of a kind::

    from cphysfno_core.testing import check_structure
    check_structure(MyBuilding())

and :func:`parametrize_with_checks` makes each check of each component its own pytest
case. The checks use small inputs (a few records, a few hundred samples) so that they run
in seconds.
"""

from .ground_motion import check_ground_motion_source
from .helpers import small_motions
from .operator import check_operator
from .parametrize import component_checks, parametrize_with_checks
from .preprocessor import check_preprocessor
from .refiner import check_refiner
from .story_law import check_story_law
from .structure import check_structure

__all__ = [
    "check_ground_motion_source",
    "check_operator",
    "check_preprocessor",
    "check_refiner",
    "check_story_law",
    "check_structure",
    "component_checks",
    "parametrize_with_checks",
    "small_motions",
]
