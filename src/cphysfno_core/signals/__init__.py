"""Time histories with their time step, the package's errors, linear systems, stories,
resampling and intensity measures: the bottom layer, which imports no other part of the package.

A plugin may import from here (``from cphysfno_core.signals import response_spectrum``)
as from ``cphysfno_core`` itself.
"""

from .at2 import read_at2
from .cpus import record_slices, run_in_slices, usable_cpus
from .errors import (
    CapabilityError,
    ConfigError,
    CphysfnoError,
    CphysfnoWarning,
    DatasetError,
    ExtrapolationWarning,
    InputError,
    MainGuardError,
    NotFittedError,
    PluginError,
    RegistryError,
    check_main_guard,
)
from .histories import (
    GroundMotions,
    Record,
    ResponseChannel,
    Responses,
    TimeGrid,
    as_ground_motions,
    check_finite,
    check_time_step,
)
from .intensity import (
    STANDARD_GRAVITY,
    ResponseSpectrum,
    SpectrumBand,
    oscillator_displacement,
    peak_ground_acceleration,
    peak_ground_velocity,
    response_spectrum,
    velocity_displacement,
)
from .linear_system import LinearSystem, Rayleigh
from .pushover import (
    StoryPushover,
    coupling_story_shear,
    cyclic_protocol,
    first_mode_pattern,
    floor_masses,
    floor_stiffness,
    lateral_pattern,
    monotonic_protocol,
)
from .resampling import resample, same_step
from .stories import Stories

__all__ = [
    "STANDARD_GRAVITY",
    "CapabilityError",
    "ConfigError",
    "CphysfnoError",
    "CphysfnoWarning",
    "DatasetError",
    "ExtrapolationWarning",
    "GroundMotions",
    "InputError",
    "MainGuardError",
    "LinearSystem",
    "NotFittedError",
    "PluginError",
    "Rayleigh",
    "Record",
    "RegistryError",
    "ResponseSpectrum",
    "ResponseChannel",
    "Responses",
    "SpectrumBand",
    "Stories",
    "StoryPushover",
    "TimeGrid",
    "as_ground_motions",
    "check_finite",
    "check_main_guard",
    "check_time_step",
    "coupling_story_shear",
    "cyclic_protocol",
    "first_mode_pattern",
    "floor_masses",
    "floor_stiffness",
    "oscillator_displacement",
    "lateral_pattern",
    "monotonic_protocol",
    "peak_ground_acceleration",
    "peak_ground_velocity",
    "read_at2",
    "record_slices",
    "resample",
    "response_spectrum",
    "run_in_slices",
    "same_step",
    "usable_cpus",
    "velocity_displacement",
]
