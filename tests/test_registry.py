import types
from pathlib import Path

import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core.app.cli import main
from cphysfno_core.config import ExperimentConfig
from cphysfno_core.plugin import Registry, get_registry, hookimpl


def test_create_builds_a_validated_component(toy_registry):
    structure = cp.create("structure", "toy-structure", cubic=2.0)
    assert structure.params.cubic == 2.0
    assert structure.get_params() == {"frequencies_hz": [1.0, 3.0], "cubic": 2.0, "delay_s": 0.0}


def test_unknown_name_lists_the_known_ones(toy_registry):
    with pytest.raises(cp.RegistryError, match="unknown structure 'nope'.*toy-structure"):
        cp.create("structure", "nope")


def test_unknown_kind_is_an_error(toy_registry):
    with pytest.raises(cp.RegistryError, match="unknown component kind 'solver'"):
        cp.create("solver", "x")


def test_bad_parameter_names_the_field(toy_registry):
    with pytest.raises(cp.ConfigError, match=r"toy-structure.cubc: unknown field"):
        cp.create("structure", "toy-structure", cubc=1.0)
    with pytest.raises(cp.ConfigError, match=r"toy-operator.width: Input should be greater"):
        cp.create("operator", "toy-operator", in_channels=2, out_channels=1, width=0)


def _toy_names():
    hooks = (
        toy_components.cphysfno_structures,
        toy_components.cphysfno_ground_motions,
        toy_components.cphysfno_preprocessors,
        toy_components.cphysfno_operators,
        toy_components.cphysfno_refiners,
    )
    return {component.name for hook in hooks for component in hook()}


def _plugin(name, **hooks):
    module = types.ModuleType(name)
    for hook, value in hooks.items():
        setattr(module, hook, hookimpl(value))
    return module


def test_a_name_claimed_twice_names_both_providers():
    twin = _plugin("twin", cphysfno_structures=lambda: [toy_components.ToyStructure])
    registry = Registry(autoload=False, plugins=(toy_components,))
    registry.register(twin, distribution="twin-dist 9.9")
    with pytest.raises(cp.RegistryError, match="provided by both.*twin-dist 9.9"):
        registry.create("structure", "toy-structure")
    assert ("structure", "toy-structure") in registry.clashes()
    assert registry.names("ground_motion") == sorted(
        source.name for source in toy_components.cphysfno_ground_motions()
    )


def test_a_broken_plugin_is_reported_and_the_rest_still_work():
    def explode():
        raise RuntimeError("boom")

    broken = _plugin("broken", cphysfno_operators=explode)
    not_a_class = _plugin("odd", cphysfno_refiners=lambda: [object])
    registry = Registry(autoload=False, plugins=(toy_components, broken, not_a_class))
    registry.register("no_such_module_anywhere")
    errors = {b.plugin: b.error for b in registry.broken}
    assert "RuntimeError: boom" in errors["broken"]
    assert "not a subclass of Refiner" in errors["odd"]
    assert "ModuleNotFoundError" in errors["no_such_module_anywhere"]
    assert registry.create("structure", "toy-structure").name == "toy-structure"
    with pytest.raises(cp.RegistryError, match="failed to load"):
        registry.create("operator", "fno")


def test_autoload_can_be_disabled_and_plugins_named(monkeypatch):
    from cphysfno_core.api.registry import get_registry, set_registry

    monkeypatch.setenv("CPHYSFNO_DISABLE_PLUGIN_AUTOLOAD", "1")
    monkeypatch.setenv("CPHYSFNO_PLUGINS", "toy_components")
    set_registry(None)
    try:
        registry = get_registry()
        names = {e.name for e in registry.entries()}
        assert names == _toy_names()
    finally:
        set_registry(None)


def test_plugins_command_lists_components_parameters_and_broken(toy_registry, capsys):
    toy_registry.register(
        _plugin("broken", cphysfno_operators=lambda: 1 / 0), distribution="bad-dist 0.1"
    )
    assert main(["plugins"]) == 0
    out = capsys.readouterr().out
    assert "structure:" in out and "toy-structure" in out
    assert "parameters: frequencies_hz=(1.0, 3.0), cubic=0.0, delay_s=0.0" in out
    assert "broken:" in out and "bad-dist 0.1: ZeroDivisionError" in out


def test_real_entry_points_are_found():
    registry = Registry()
    kinds = {e.kind for e in registry.entries()}
    assert kinds, "no plugin found through the cphysfno entry-point group"
    assert all(e.distribution.startswith("cphysfno-") for e in registry.entries())
    assert not registry.broken, registry.broken


def test_one_list_of_kinds_makes_the_hooks_and_the_config_sections():
    from cphysfno_core.api import KINDS
    from cphysfno_core.api.registry import plugin_manager

    hooks = {name for name in vars(plugin_manager().hook) if name.startswith("cphysfno_")}
    assert hooks == {kind.hook for kind in KINDS}
    sections = {k.name for k in KINDS} & set(ExperimentConfig.model_fields)
    assert sections == {"structure", "ground_motion", "preprocessor", "operator", "refiner"}
    with pytest.raises(cp.RegistryError, match="unknown component kind 'story'.*structure"):
        cp.create("story", "x")


def test_the_readme_lists_every_registered_component(capsys):
    """The README's components table is `cphysfno plugins --markdown`, so it cannot go stale
    (regenerate it with that command when a component is added)."""
    readme = (Path(__file__).parents[1] / "README.md").read_text()
    start = readme.index("| kind | name | distribution | what |")
    end = readme.index("<!-- end of generated table -->")
    assert main(["plugins", "--markdown"]) == 0
    printed = capsys.readouterr().out.strip()
    assert readme[start:end].strip() == printed
    assert printed.count("\n") - 1 == len(get_registry().entries())


def test_version(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"cphysfno {cp.__version__}"


def test_every_kind_has_its_hook_specification_written_out():
    import inspect

    from cphysfno_core.api import hookspecs
    from cphysfno_core.api.kinds import KINDS

    written = {
        name
        for name, member in vars(hookspecs.Specifications).items()
        if isinstance(member, staticmethod)
    }
    assert written == {kind.hook for kind in KINDS}
    for kind in KINDS:
        spec = getattr(hookspecs.Specifications, kind.hook)
        assert kind.base.__name__ in inspect.getdoc(spec)
        assert inspect.signature(spec).parameters == {}
