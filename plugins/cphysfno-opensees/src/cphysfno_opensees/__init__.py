"""OpenSees structures for cphysfno.

:func:`import_opensees` returns ``openseespy.opensees`` with its bundled libraries loaded
first: use it to run a model script directly, beside cphysfno, where a plain ``import
openseespy.opensees`` fails (Debian without ``libblas3``).
"""

from .loader import import_opensees

__all__ = ["import_opensees"]
