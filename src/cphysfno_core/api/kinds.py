"""The kinds of component: one list, read by the hook specifications, the registry, the
experiment config and the command line. A new kind is one more entry here (and its base
class in :mod:`.interfaces`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..signals.errors import RegistryError
from .interfaces import GroundMotionSource, NeuralOperator, PhysicsPreprocessor, Refiner, Structure
from .story_law import StoryLaw


@dataclass(frozen=True)
class Kind:
    """A kind of component.

    Attributes:
        name: the kind's name in the registry (``create(name, ...)``) and its section in an
            experiment config.
        base: the class every component of the kind subclasses.
        hook: the plugin hook that hands over the kind's component classes.
        what: the components in words, for the hook's documentation.
    """

    name: str
    base: type
    hook: str
    what: str


KINDS: tuple[Kind, ...] = (
    Kind("structure", Structure, "cphysfno_structures", "Structure classes"),
    Kind("ground_motion", GroundMotionSource, "cphysfno_ground_motions", "Ground-motion sources"),
    Kind("preprocessor", PhysicsPreprocessor, "cphysfno_preprocessors", "Physics preprocessors"),
    Kind("operator", NeuralOperator, "cphysfno_operators", "Neural operator classes"),
    Kind("refiner", Refiner, "cphysfno_refiners", "Refiner classes"),
    Kind("story_law", StoryLaw, "cphysfno_story_laws", "Story laws of shear buildings"),
)

KIND_NAMES: tuple[str, ...] = tuple(kind.name for kind in KINDS)


def kind_named(name: str) -> Kind:
    """The :class:`Kind` called ``name``.

    Raises:
        RegistryError: no kind has that name (the message lists them).
    """
    for kind in KINDS:
        if kind.name == name:
            return kind
    raise RegistryError(f"unknown component kind '{name}': use one of {', '.join(KIND_NAMES)}")
