"""Import OpenSeesPy reliably.

The ``openseespy`` wheel for Linux ships BLAS, LAPACK and the Fortran runtime in
``openseespylinux/lib``, but its ``opensees.so`` does not find them on systems without
those libraries installed (Debian without ``libblas3``). Loading them globally first, in
dependency order, lets the extension resolve its symbols from the bundled copies.
"""

from __future__ import annotations

import ctypes
import importlib
import importlib.util
import os
from types import ModuleType

from cphysfno_core import PluginError

BUNDLED_LIBRARIES = (
    "libquadmath.so.0",
    "libgfortran.so.4",
    "libgomp.so.1",
    "libblas.so.3",
    "liblapack.so.3",
)
HOW_TO_FIX = (
    "install it with `pip install 'openseespy>=3.7,<3.8'` (or run ./install.sh), or install "
    "the system BLAS/LAPACK: `apt-get install libblas3 liblapack3`"
)


def import_opensees() -> ModuleType:
    """Return ``openseespy.opensees``, its bundled shared libraries loaded first.

    Raises:
        PluginError: OpenSeesPy is missing or its extension cannot be loaded; the message
            says in one line how to fix it.
    """
    spec = importlib.util.find_spec("openseespylinux")
    if spec is not None and spec.submodule_search_locations:
        folder = os.path.join(list(spec.submodule_search_locations)[0], "lib")
        for name in BUNDLED_LIBRARIES:
            path = os.path.join(folder, name)
            if os.path.exists(path):
                ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
    try:
        return importlib.import_module("openseespy.opensees")
    except (ImportError, OSError) as error:
        raise PluginError(f"OpenSeesPy will not import ({error}): {HOW_TO_FIX}") from error
