"""A user's model in OpenSees' domain: built by its script, brought to rest under gravity,
and set up for a transient analysis under a ground motion."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..messages import captured, said
from .damping import DampingSetup
from .responses import ResponseParams, check_responses
from .source import BUILD, ScriptError, call, check_arguments, load

LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}
"""Metres per length unit of a model."""

HANDLERS = ("Plain", "Penalty", "Transformation", "Lagrange")
"""The OpenSees constraint handlers a model may be analysed with."""

GRAVITY_STEPS = 10
"""Load steps of the gravity analysis the framework runs (load factor 0.1 each)."""

EXCITATION_TAG = 2_147_480_000
"""Tag of the ground motion's time series and load pattern (kept clear of a script's)."""


@dataclass(frozen=True)
class ModelSpec:
    """Everything a worker process needs to build and analyse a user's model.

    Attributes:
        script: absolute path of the script.
        outputs: ``(node, dof)`` of each output, dof counted from 1.
        excitation_dof: the DOF along which the ground moves (UniformExcitation).
        gravity: name of the script's gravity function, or None.
        metres_per_unit: metres per length unit of the model.
        tolerance: Newton's tolerance on the norm of the displacement increment, in the
            model's length unit.
        max_iterations: Newton iterations per step before the fallbacks take over.
        constraints: the ``ops.constraints`` arguments of every analysis (empty until
            chosen).
        responses: the named responses read at every step beside the outputs.
        arguments: ``(keyword, value)`` pairs given to ``build()`` and the gravity
            function, each the keywords its signature accepts (numbers in the script's
            units).
    """

    script: Path
    outputs: tuple[tuple[int, int], ...]
    excitation_dof: int
    gravity: str | None
    metres_per_unit: float
    tolerance: float
    max_iterations: int
    constraints: tuple[Any, ...] = ()
    responses: tuple[ResponseParams, ...] = ()
    arguments: tuple[tuple[str, float], ...] = ()

    @property
    def functions(self) -> tuple[str, ...]:
        """The script's functions the model is built with: ``build`` and the gravity
        function, if any."""
        return (BUILD,) if self.gravity is None else (BUILD, self.gravity)

    @property
    def keywords(self) -> dict[str, float]:
        """:attr:`arguments` as keywords (numbers in the script's units)."""
        return dict(self.arguments)

    def with_constraints(self, constraints: tuple[Any, ...]) -> ModelSpec:
        return replace(self, constraints=tuple(constraints))


@dataclass(frozen=True)
class Built:
    """A model built in the domain and at rest under its gravity loads.

    Attributes:
        ndm: spatial dimensions of the model.
        at_rest: ``[n_outputs]`` displacements of the outputs at rest (model units).
        translations: ``[n_outputs]`` whether each output is a translation (else a
            rotation).
    """

    ndm: int
    at_rest: np.ndarray
    translations: np.ndarray


def build_model(
    ops: Any,
    spec: ModelSpec,
    constraints: tuple[Any, ...] | None = None,
    *,
    gravity: bool = True,
) -> Built:
    """Wipe the domain, run the script's ``build()`` with its keywords of ``spec.arguments``,
    check the outputs and, unless ``gravity`` is False, bring the model to rest under its
    gravity loads (:func:`apply_gravity`, analysed with the handler ``constraints``, default
    ``spec.constraints``).

    Raises:
        ScriptError: the script or its ``build()`` raises, a keyword of ``spec.arguments``
            is taken by no function of the script, the model has no nodes, an output or a
            named response names a node, DOF or element the model does not have, the
            excitation DOF is not one of its nodes', or the gravity analysis fails.
    """
    module = load(spec.script)
    check_arguments(module, spec.script, spec.functions, spec.keywords)
    ops.wipe()
    with captured() as messages:
        try:
            call(module, spec.script, BUILD, spec.keywords)
        except ScriptError as error:
            raise ScriptError(f"{error}{said(messages)}") from None
    nodes = set(ops.getNodeTags())
    if not nodes:
        raise ScriptError(f"build() of OpenSees script {spec.script} created no nodes")
    ndm = int(ops.getNDM()[0])
    translations = []
    for node, dof in spec.outputs:
        if node not in nodes:
            raise ScriptError(
                f"outputs: the model of OpenSees script {spec.script} has no node {node}"
            )
        ndf = int(ops.getNDF(node)[0])
        if not 1 <= dof <= ndf:
            raise ScriptError(
                f"outputs: node {node} of OpenSees script {spec.script} has DOFs 1 to {ndf}, "
                f"not {dof}"
            )
        translations.append(dof <= ndm)
    check_responses(ops, spec.responses, spec.script)
    widest = max(int(ops.getNDF(node)[0]) for node in nodes)
    if spec.excitation_dof > widest:
        raise ScriptError(
            f"excitation_dof = {spec.excitation_dof}: the nodes of OpenSees script "
            f"{spec.script} have at most {widest} DOFs"
        )
    if gravity and spec.gravity is not None:
        apply_gravity(ops, spec, spec.constraints if constraints is None else constraints)
    return Built(ndm, output_displacements(ops, spec), np.asarray(translations, dtype=bool))


def output_displacements(ops: Any, spec: ModelSpec) -> np.ndarray:
    """``[n_outputs]`` the outputs' displacements now, in the model's units."""
    return np.array([ops.nodeDisp(node, dof) for node, dof in spec.outputs], dtype=np.float64)


def apply_gravity(ops: Any, spec: ModelSpec, constraints: tuple[Any, ...]) -> None:
    """Call the script's gravity function with its keywords of ``spec.arguments``; unless
    it has analysed its loads itself, analyse them statically (Newton,
    :data:`GRAVITY_STEPS` load steps, the handler ``constraints``); then hold them constant
    with the time reset to 0 (``loadConst -time 0.0``) and wipe the analysis.

    A function has analysed its loads when the analysis time has moved, or when the model
    has moved: the idiom of the OpenSees examples analyses the loads and holds them with
    ``loadConst -time 0.0``, which resets the clock but leaves the deformed state; such a
    state is never analysed again (with a rigid link under a Penalty handler a second
    analysis of a held state can fail to converge).

    Raises:
        ScriptError: the function raises, or the gravity analysis does not converge.
    """
    assert spec.gravity is not None
    module = load(spec.script)
    with captured() as messages:
        try:
            call(module, spec.script, spec.gravity, spec.keywords)
        except ScriptError as error:
            raise ScriptError(f"{error}{said(messages)}") from None
        if ops.getTime() == 0.0 and not _has_moved(ops):
            ops.wipeAnalysis()
            ops.constraints(*constraints)
            ops.numberer("RCM")
            ops.system("BandGeneral")
            ops.test("NormDispIncr", spec.tolerance, spec.max_iterations)
            ops.algorithm("Newton")
            ops.integrator("LoadControl", 1.0 / GRAVITY_STEPS)
            ops.analysis("Static")
            if ops.analyze(GRAVITY_STEPS) != 0:
                raise ScriptError(
                    f"the gravity analysis of OpenSees script {spec.script} (the loads of "
                    f"{spec.gravity}(), {GRAVITY_STEPS} load steps, Newton, constraints "
                    f"{constraints[0]}) did not converge at load factor "
                    f"{ops.getTime():.2f}: can the model carry its gravity loads?"
                    f"{said(messages)}"
                )
        ops.loadConst("-time", 0.0)
        ops.wipeAnalysis()


def _has_moved(ops: Any) -> bool:
    """Whether any node of the model is displaced from where it was built."""
    return any(any(value != 0.0 for value in ops.nodeDisp(node)) for node in ops.getNodeTags())


def start_transient(
    ops: Any, spec: ModelSpec, damping: DampingSetup, acceleration: np.ndarray, dt: float
) -> None:
    """The damping (:meth:`DampingSetup.apply`), the ground acceleration (in the model's
    units, linear between samples) as a UniformExcitation along ``spec.excitation_dof``,
    and the transient analysis: Newmark's average acceleration rule, Newton, the handler
    ``spec.constraints``."""
    damping.apply(ops)
    values = np.asarray(acceleration, dtype=np.float64)
    ops.timeSeries("Path", EXCITATION_TAG, "-dt", dt, "-values", *values)
    ops.pattern("UniformExcitation", EXCITATION_TAG, spec.excitation_dof, "-accel", EXCITATION_TAG)
    ops.constraints(*spec.constraints)
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test(*transient_test(spec))
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def transient_test(spec: ModelSpec) -> tuple[Any, ...]:
    """The ``ops.test`` arguments of the transient analysis: the norm of the displacement
    increment below ``spec.tolerance`` (model units) within ``spec.max_iterations``."""
    return ("NormDispIncr", spec.tolerance, spec.max_iterations)
