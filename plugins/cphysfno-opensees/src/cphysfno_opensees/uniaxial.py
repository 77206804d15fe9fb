"""An OpenSees uniaxial material driven through a strain history, alone: the reference
a story law is checked against."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .loader import import_opensees


def uniaxial_stress(material: Sequence[Any], strains: np.ndarray) -> np.ndarray:
    """``[n]`` the stress of ``uniaxialMaterial(*material)`` (its type, its tag, then its
    arguments) as OpenSees' ``testUniaxialMaterial`` drives it through ``strains [n]``,
    one committed state per strain, in the material's own units. Runs in this process:
    the OpenSees domain is wiped before and after.
    """
    ops = import_opensees()
    ops.wipe()
    try:
        ops.uniaxialMaterial(*material)
        ops.testUniaxialMaterial(material[1])
        stress = []
        for strain in np.asarray(strains, dtype=np.float64):
            ops.setStrain(float(strain))
            stress.append(ops.getStress())
    finally:
        ops.wipe()
    return np.array(stress)
