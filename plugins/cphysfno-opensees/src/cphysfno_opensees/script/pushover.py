"""The static pushover of a user's model (the ``pushover`` capability of ``opensees-model``):
the model at rest under its gravity loads, pushed in a worker process by a lateral load on
its floors."""

from __future__ import annotations

import numpy as np

from cphysfno_core.plugin import LinearSystem, Stories, StoryPushover

from ..loader import import_opensees
from ..pushover import STRENGTH_LOSS, Pushed, push, story_pushover_by
from ..runner import call_in_worker
from .model import ModelSpec, build_model
from .source import ScriptError


def story_pushover(
    spec: ModelSpec,
    stories: Stories,
    system: LinearSystem,
    roof_drift_ratio: np.ndarray,
    pattern: np.ndarray | None,
) -> StoryPushover:
    """Each story's shear-drift curve of a user's model pushed along ``roof_drift_ratio``.

    Args:
        spec: the model, its constraint handler chosen.
        stories: its stories (heights in m).
        system: its linear system at the gravity state (SI lengths).
        roof_drift_ratio: ``[p]`` roof displacement over the building's height, from 0.
        pattern: ``[d]`` lateral load on the floors, bottom up, or ``None``.

    The model is built and brought to rest under its gravity loads (held constant, so that
    P-Delta acts as the script's transformations have it); a lateral load of shape
    ``pattern`` (default: the first mode of the linear system at the gravity state times
    the floor masses) acts along ``excitation_dof`` on the floor nodes, the outputs at the
    tops of the stories; the roof follows the protocol by displacement control (Newton,
    the model's constraint handler and tolerance, a step cut into ten where it does not
    converge whole). The analysis stops early, saying so in ``stopped``, where a step does
    not converge or the base shear drops by
    :data:`~cphysfno_opensees.pushover.STRENGTH_LOSS` on a new excursion.
    Story shears are the lateral loads above each story; floor masses are the linear
    system's, condensed onto the floors (:func:`~cphysfno_core.signals.floor_masses`),
    in the script's force unit times s^2/m (kg for a script in SI units).

    Raises:
        ScriptError: the stories are not floors one above the other, each the top output
            along ``excitation_dof``.
        InputError: ``pattern`` is not one value >= 0 per floor of positive sum.
    """
    tops = [spec.outputs[i] for i in stories.upper]
    if not stories.is_stacked or any(dof != spec.excitation_dof for _, dof in tops):
        raise ScriptError(
            f"a pushover of OpenSees script {spec.script} needs stories one above the other "
            f"whose tops are outputs along excitation_dof {spec.excitation_dof}; got tops {tops}"
        )
    floors = tuple(node for node, _ in tops)

    def pusher(shape: np.ndarray, roof: np.ndarray) -> Pushed:
        return call_in_worker(
            push_model, spec, floors, shape, roof,
            description=f"pushing the model of OpenSees script {spec.script}",
        )  # fmt: skip

    return story_pushover_by(
        pusher, stories, system, roof_drift_ratio, pattern, spec.metres_per_unit
    )


def push_model(
    spec: ModelSpec, floors: tuple[int, ...], pattern: np.ndarray, roof: np.ndarray
) -> Pushed:
    """Build the model at rest under gravity and :func:`~cphysfno_opensees.pushover.push`
    it (runs in a worker process)."""
    ops = import_opensees()
    try:
        build_model(ops, spec)
        ops.constraints(*spec.constraints)
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", spec.tolerance, spec.max_iterations)
        ops.algorithm("Newton")
        return push(ops, list(floors), spec.excitation_dof, pattern, roof, STRENGTH_LOSS)
    finally:
        ops.wipe()
