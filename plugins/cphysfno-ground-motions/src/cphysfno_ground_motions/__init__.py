"""Ground-motion sources for cphysfno: white noise, spectrum-compatible synthetic records,
and recorded ones (FEMA P695 sets, PEER NGA-West2 AT2 files)."""

from cphysfno_core.signals import read_at2

from .errors import GroundMotionWarning
from .fema import load_fema_p695
from .flatfile import read_flatfile
from .plots import plot_records, plot_spectra
from .record import Record
from .recorded import Recorded
from .spectrum_compatible import SpectrumCompatible
from .target import TargetSpectrum, bssa14_target
from .white_noise import WhiteNoise

__all__ = [
    "GroundMotionWarning",
    "Record",
    "Recorded",
    "SpectrumCompatible",
    "TargetSpectrum",
    "WhiteNoise",
    "bssa14_target",
    "load_fema_p695",
    "plot_records",
    "plot_spectra",
    "read_at2",
    "read_flatfile",
]
