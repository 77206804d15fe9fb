"""The label of a model in reports, ``metrics.json``, ``study.json`` and under
``models/``: :class:`ModelLabel`.

A label reads, from the inside out: the operator's name alone for the baseline (``fno``);
``c-phys<operator>-<preprocessor>`` for a C-Phys model (``c-physfno-els``); ``-residual``
behind it for the residual formulation; ``-params`` behind that for a model that takes the
structure's parameters as inputs; ``refined-`` in front when refined. The physics
response of a preprocessor alone, untrained, has the row ``physics-<preprocessor>``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, replace

from ..api.registry import get_registry

COMPOSITE = "c-phys"
RESIDUAL = "-residual"
PARAMETERS = "-params"
REFINED = "refined-"
PHYSICS = "physics-"


@dataclass(frozen=True)
class ModelLabel:
    """A model's label, and what it says of the model.

    Attributes:
        operator: the neural operator's registry name; None for the row of a physics
            preprocessor alone.
        preprocessor: the physics preprocessor's registry name; None for the baseline.
        refined: whether a refiner gives the model its intervals.
        residual: whether the operator learns the residual ``u - z``.
        parameters: whether the operator takes the structure's parameters as inputs.
    """

    operator: str | None
    preprocessor: str | None = None
    refined: bool = False
    residual: bool = False
    parameters: bool = False

    def __post_init__(self) -> None:
        if not (self.operator or self.preprocessor):
            raise ValueError("a model label names an operator, a preprocessor or both")
        if self.operator is None and (self.refined or self.residual or self.parameters):
            raise ValueError(
                "a physics preprocessor alone is neither refined nor residual, and takes no "
                "parameter inputs"
            )

    @classmethod
    def physics(cls, preprocessor: str) -> ModelLabel:
        """The row of ``preprocessor``'s physics response alone: ``physics-<name>``."""
        return cls(None, preprocessor)

    @classmethod
    def parse(cls, text: str, operators: Iterable[str] | None = None) -> ModelLabel:
        """The label ``text`` reads as; ``str`` of the result is ``text``.

        Args:
            text: a label, e.g. ``refined-c-physfno-els-residual``.
            operators: the operator names that may begin a C-Phys label's
                ``<operator>-<preprocessor>`` (both names may hold hyphens); default
                those registered. The longest that fits is taken; where none does, the
                operator's name is taken to end at the first hyphen.

        Raises:
            ValueError: ``text`` is no label (empty, or a C-Phys label without a
                preprocessor, or a refined or residual physics row).
        """
        body = text
        refined = body.startswith(REFINED)
        body = body.removeprefix(REFINED)
        parameters = body.endswith(PARAMETERS)
        body = body.removesuffix(PARAMETERS)
        residual = body.endswith(RESIDUAL)
        body = body.removesuffix(RESIDUAL)
        if body.startswith(PHYSICS):
            return cls(None, body.removeprefix(PHYSICS) or None, refined, residual, parameters)
        if not body.startswith(COMPOSITE):
            return cls(body or None, None, refined, residual, parameters)
        parts = body.removeprefix(COMPOSITE)
        names = get_registry().names("operator") if operators is None else operators
        fitting = [name for name in names if parts.startswith(f"{name}-")]
        operator = max(fitting, key=len) if fitting else parts.partition("-")[0]
        preprocessor = parts.removeprefix(f"{operator}-")
        if not operator or not preprocessor or preprocessor == parts:
            raise ValueError(f"'{text}' is no model label: c-phys<operator>-<preprocessor>")
        return cls(operator, preprocessor, refined, residual, parameters)

    def __str__(self) -> str:
        if self.operator is None:
            return f"{PHYSICS}{self.preprocessor}"
        label = self.operator
        if self.preprocessor is not None:
            label = f"{COMPOSITE}{self.operator}-{self.preprocessor}"
        label += RESIDUAL if self.residual else ""
        label += PARAMETERS if self.parameters else ""
        return f"{REFINED}{label}" if self.refined else label

    @property
    def is_physics(self) -> bool:
        """Whether this is the row of a physics preprocessor alone (nothing trained)."""
        return self.operator is None

    @property
    def is_trained(self) -> bool:
        """Whether the row is a trained model (the baseline or a C-Phys model)."""
        return self.operator is not None

    @property
    def is_composite(self) -> bool:
        """Whether the model is a C-Phys model: an operator on a preprocessor's response."""
        return self.operator is not None and self.preprocessor is not None

    @property
    def residual_twin(self) -> ModelLabel:
        """The same model in the residual formulation."""
        return replace(self, residual=True)
