"""What a uniaxial material that fibres can be made of provides: the protocol that
:class:`~.steel02.Steel02Parameters` and :class:`~.concrete04.Concrete04Parameters`
follow."""

from __future__ import annotations

from dataclasses import astuple
from typing import Any, ClassVar

import numpy as np


class UniaxialMaterial:
    """The parameters of a uniaxial material whose law is compiled in this package.

    A subclass is a frozen dataclass whose fields are, by name and in order, the arguments
    of OpenSees' ``uniaxialMaterial <opensees_name> tag ...`` (SI units), validated when it
    is made. It packs them into the flat float64 vector its compiled ``trial`` law reads
    (the one place, with ``trial``, that knows that vector's slots), gives the state of a
    virgin fibre, and defines the same material in OpenSees.
    """

    opensees_name: ClassVar[str]
    """The material's name in OpenSees."""

    def packed(self) -> np.ndarray:
        """``[n_parameters]`` float64: the parameter vector ``p`` of the compiled law."""
        raise NotImplementedError

    def initial_state(self) -> np.ndarray:
        """``[n_state]`` float64: the committed state of a virgin fibre."""
        raise NotImplementedError

    def define(self, ops: Any, tag: int) -> None:
        """Define the material in OpenSees (``ops``) as uniaxial material ``tag``."""
        ops.uniaxialMaterial(self.opensees_name, tag, *astuple(self))
