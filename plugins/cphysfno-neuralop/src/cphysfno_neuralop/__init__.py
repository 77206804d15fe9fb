"""``neuralop.models.FNO`` (the neuraloperator library) as cphysfno operator ``neuralop-fno``."""

from .adapter import NeuralopFNO, NeuralopFNOParams

__all__ = ["NeuralopFNO", "NeuralopFNOParams"]
