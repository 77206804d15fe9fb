"""The public API by audience: ``cphysfno_core`` for users, ``cphysfno_core.plugin`` for
plugin authors. A name added to or removed from either is a decision, made here."""

import inspect
import re
import types
from pathlib import Path

import cphysfno_core
import cphysfno_core.plugin
import cphysfno_core.testing

ROOT = Path(__file__).resolve().parents[1]

ERRORS = set(
    """CapabilityError ConfigError CphysfnoError CphysfnoWarning DatasetError
    ExtrapolationWarning InputError MainGuardError NotFittedError PluginError
    RegistryError""".split()
)

USERS = ERRORS | set(
    """CompositeModel GroundMotions Responses compose create generate_dataset load_config
    load_dataset parse_config""".split()
)

PLUGIN_AUTHORS = set(
    """GroundMotionSource NeuralOperator PhysicsPreprocessor Refiner StoryLaw Structure
    RestoringForce LawFunctions Params per_story validate_params
    Registry get_registry hookimpl
    LinearSystem Rayleigh ResponseChannel Stories StoryPushover TimeGrid check_finite
    check_main_guard check_time_step motion_spectra native_bfloat16
    parametrize_with_checks""".split()
)


def test_the_users_api_is_these_names():
    assert sorted(cphysfno_core.__all__) == sorted(USERS)
    assert len(cphysfno_core.__all__) == len(USERS)  # no name twice
    assert len(cphysfno_core.__all__) <= 20


def test_the_plugin_authors_api_is_these_names():
    assert sorted(cphysfno_core.plugin.__all__) == sorted(PLUGIN_AUTHORS)
    assert len(cphysfno_core.plugin.__all__) == len(PLUGIN_AUTHORS)


def test_the_edp_module_is_reached_from_the_package():
    assert isinstance(cphysfno_core.edp, types.ModuleType)


def test_the_two_audiences_share_no_name():
    # what a plugin shares with users it imports from cphysfno_core
    assert not USERS & PLUGIN_AUTHORS


def test_no_internal_name_is_left_at_the_top_level():
    public = {
        name
        for name, value in vars(cphysfno_core).items()
        if not name.startswith("_") and not isinstance(value, types.ModuleType)
    }
    assert public == USERS


def _documented(module, name):
    value = getattr(module, name)
    if isinstance(value, types.ModuleType):
        return bool(value.__doc__)
    return bool(inspect.getdoc(value))


def test_every_public_name_has_a_docstring():
    for module in (cphysfno_core, cphysfno_core.plugin):
        assert module.__doc__
        missing = [n for n in module.__all__ if not _documented(module, n)]
        assert not missing, f"{module.__name__}: no docstring for {missing}"


def test_every_plugin_authors_name_is_in_the_api_reference():
    api = (ROOT / "docs" / "reference" / "api.md").read_text()
    directives = set(re.findall(r"^::: ([\w.]+)", api, re.M))
    assert "cphysfno_core.plugin" in directives and "cphysfno_core.testing" in directives
    testing = set(cphysfno_core.testing.__all__)
    missing = [
        name
        for name in cphysfno_core.plugin.__all__
        if f"cphysfno_core.plugin.{name}" not in directives
        and f"cphysfno_core.{name}" not in directives
        and name not in testing
    ]
    assert not missing, f"add ::: cphysfno_core.plugin.<name> to api.md for {missing}"
