"""Exception types a user can trigger. Every message says what to change."""

from __future__ import annotations


class CphysfnoError(Exception):
    """Base class of every error this package raises on purpose."""


class ConfigError(CphysfnoError, ValueError):
    """A configuration field is missing, unknown or out of range."""


class RegistryError(CphysfnoError, LookupError):
    """A component name is unknown, taken twice, or its plugin failed to load."""


class InputError(CphysfnoError, ValueError):
    """An array handed to the framework has the wrong shape, NaN/Inf, or a bad time step."""


class CapabilityError(CphysfnoError, TypeError):
    """A component needs a capability that another component does not provide."""


class DatasetError(CphysfnoError, OSError):
    """A dataset file is missing, incomplete or does not match the configuration."""


class NotFittedError(CphysfnoError, RuntimeError):
    """A component was used before ``fit``."""


class PluginError(CphysfnoError, RuntimeError):
    """A plugin broke its contract (for example returned an array of the wrong shape)."""


class CphysfnoWarning(UserWarning):
    """Something was done only in part (fewer records, a looser match): the message says
    what and why."""


class ExtrapolationWarning(CphysfnoWarning):
    """Records lie far outside what a model was trained on, so its predictions for them
    are extrapolations."""
