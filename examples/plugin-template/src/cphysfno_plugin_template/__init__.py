"""A third-party cphysfno plugin: structure ``duffing-chain`` and ground motion
``kanai-tajimi``."""

from .duffing import DuffingChain, DuffingChainParams
from .kanai_tajimi import KanaiTajimi, KanaiTajimiParams, kanai_tajimi_psd, kanai_tajimi_variance

__all__ = [
    "DuffingChain",
    "DuffingChainParams",
    "KanaiTajimi",
    "KanaiTajimiParams",
    "kanai_tajimi_psd",
    "kanai_tajimi_variance",
]
