"""Nonlinear stick: a shear building whose story laws are fitted to the structure's pushover."""

from __future__ import annotations

import dataclasses
import json
import warnings
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field

from cphysfno_core import ConfigError, CphysfnoWarning, GroundMotions, create, edp, plugin
from cphysfno_core.plugin import PhysicsPreprocessor, Stories, Structure
from cphysfno_core.signals import cyclic_protocol, monotonic_protocol

from .fitted import check_fitted
from .stick_calibration import (
    LAW_SPACES,
    SPRINGS_ALONE,
    IndefiniteFloorStiffness,
    StickCalibration,
    calibrate,
    first_within_tie,
    warn_where_off,
)
from .stick_figures import write_stick_artifacts
from .stick_probes import FOLLOWS, INTEGRATOR_TOLERANCE, dynamic_errors, integrator_error
from .stick_refinement import refine

DriftRatio = Annotated[float, Field(gt=0.0, le=0.2)]


class Stick(PhysicsPreprocessor):
    """``z``: the response of a nonlinear shear building (a *stick*) fitted to the structure.

    :meth:`fit` pushes the structure (capability ``pushover``) with a lateral pattern
    (``pattern``, or its first mode times its floor masses): monotonically to a roof drift
    ratio of ``target_drift_ratio``, and through one cycle at each of
    ``cycle_amplitudes``. From the curves of its stories it builds a ``shear-building``
    (:func:`~cphysfno_physics.stick_calibration.calibrate`): the floor masses, the story
    heights, initial stiffnesses that give springs alone the structure's first period, the
    structure's damping, and one story law for every story, each of ``laws`` fitted story
    by story to the monotonic and cyclic curves together (the monotonic one shows a story
    that softens past the cycles' drifts). With ``coupling`` it adds a linear coupling between the
    floors that gives the stick the structure's own stiffness at its floors (so its higher
    periods too; the springs then hold the curves less the coupling's share), or not, or
    fits both forms. The form and law are chosen by ``law_choice``: by default the pair
    whose stick is closest to the structure itself under three resonant probe pulses
    (:mod:`~cphysfno_physics.stick_probes`; the structure is analysed on them once; springs
    alone where they follow it within :data:`~.stick_probes.FOLLOWS`, as the cheaper
    stick), else the one that fits the pushovers best. With ``refine_records`` the chosen stick's
    story stiffnesses, yield drifts and post-yield ratios, then its whole law, are refined
    on the structure's response to that many synthetic records, and the refinement closer
    on records held out of the fit is kept where they confirm it
    (:mod:`~cphysfno_physics.stick_refinement`). :meth:`transform` simulates that
    building on its compiled kernel, by default on central difference where that stays
    within :data:`~.stick_probes.INTEGRATOR_TOLERANCE` of Runge-Kutta under the probe
    pulses (``integrator``); the structure is not called again.

    The stick has one degree of freedom a floor: it cannot follow torsion, strong higher
    modes or a building whose stories do not behave as shear springs (a soft first story
    that takes the whole drift, a tall flexural wall); the fit errors and the periods it
    records say how far it is from the structure.

    Fitted attributes:
        calibration_: the :class:`~cphysfno_physics.stick_calibration.StickCalibration`
            (pushovers, stiffnesses, damping, every law's fit and the chosen one),
            JSON-serialisable with its ``to_dict``.
        stick_: the ``shear-building`` that is the stick.
        floors_: ``[n_outputs]`` the stick's floor that gives each output.
    """

    name = "stick"
    requires = frozenset({"pushover", "stories", "equivalent_linear_system"})
    collapses = True

    class Params(plugin.Params):
        target_drift_ratio: DriftRatio = Field(
            0.03, description="roof drift ratio of the monotonic pushover"
        )
        cycle_amplitudes: tuple[DriftRatio, ...] = Field(
            (0.0025, 0.005, 0.01, 0.02),
            min_length=1,
            description="roof drift ratio of each cycle of the cyclic pushover, in order",
        )
        points_per_cycle: int = Field(
            80, ge=8, multiple_of=4, description="pushover steps a cycle, a multiple of 4"
        )
        laws: tuple[str, ...] = Field(
            tuple(LAW_SPACES),
            min_length=1,
            description=f"story laws to choose from: {', '.join(LAW_SPACES)}",
        )
        pattern: tuple[Annotated[float, Field(ge=0.0)], ...] | None = Field(
            None,
            description="lateral load on each floor, bottom up (None: the first mode times "
            "the floor masses)",
        )
        law_choice: Literal["pushover", "dynamic"] = Field(
            "dynamic",
            description="how the law is chosen among laws: 'pushover', the lowest "
            "worst-story fit error on the pushovers; 'dynamic', the lowest relative L2 "
            "of the stick against the structure itself under three resonant probe pulses "
            "that drive the pushover-chosen stick to the three largest cycle amplitudes "
            "(the structure is analysed on them once)",
        )
        coupling: Literal["floors", "none", "choose"] = Field(
            "choose",
            description="'floors': give the stick the structure's own stiffness at its "
            "floors, a linear coupling between the floors beside the story springs (every "
            "period of the floor-condensed structure: a frame's flexure); 'none': story "
            "springs alone (a plain shear building, whose higher periods are longer than a "
            "frame's); 'choose': fit both and keep the one law_choice ranks first, but "
            f"springs alone wherever they follow the structure within {FOLLOWS} (the "
            "cheaper stick)",
        )
        refine_records: int = Field(
            12,
            ge=0,
            description="synthetic records (spectrum-compatible) the structure is analysed "
            "on to refine each story's stiffness, yield drift and post-yield ratio, then "
            "the law's shape too, against its response, every third held out to choose "
            "between the two and check that the refinement is closer (0: the pushover fit "
            "alone)",
        )
        integrator: Literal["choose", "runge-kutta", "central-difference"] = Field(
            "choose",
            description="the stick's integrator: 'central-difference' (one evaluation of "
            "the story laws a step, several times faster), 'runge-kutta' (classical fourth "
            "order), or 'choose': central difference where the stick's response to the "
            f"probe pulses on it is within {INTEGRATOR_TOLERANCE} (relative L2) of the "
            "Runge-Kutta one, else Runge-Kutta",
        )
        tolerance: float = Field(
            0.1,
            gt=0.0,
            description="relative difference between a period or a modal damping ratio of "
            "the stick and the structure's beyond which fit warns",
        )

    def fit(self, structure: Structure) -> Stick:
        """Push the structure, fit the stick and build it.

        Raises:
            CapabilityError: the structure lacks ``pushover``, ``stories`` or
                ``equivalent_linear_system``.
            ConfigError: its stories are not floors one above the other, or an output is
                not a floor; a law is not one the calibration fits.
            IndefiniteFloorStiffness: ``coupling = "floors"`` and the structure's
                stiffness at its floors is not positive definite (``"choose"`` then keeps
                springs alone, with a warning).
        """
        self.check(structure)
        p = self.params
        edp.require_heights(structure.stories(), "the stick (a pushover by drift ratio)")
        floors = _floors(structure.stories(), structure.n_outputs, structure.name)
        pattern = None if p.pattern is None else np.asarray(p.pattern)
        backbone = structure.story_pushover(monotonic_protocol(p.target_drift_ratio), pattern)
        cyclic = structure.story_pushover(
            cyclic_protocol(p.cycle_amplitudes, p.points_per_cycle), backbone.pattern
        )
        forms = {"floors": (True,), "none": (False,), "choose": (True, False)}[p.coupling]
        try:
            candidates = [calibrate(structure, backbone, cyclic, p.laws, forms[0])]
        except IndefiniteFloorStiffness as error:
            if p.coupling != "choose":
                raise
            warnings.warn(f"{error}: the stick is springs alone", CphysfnoWarning, stacklevel=2)
            candidates = [calibrate(structure, backbone, cyclic, p.laws, False)]
        if len(forms) > 1 and candidates[0].coupling is not None:  # a shear building has none
            candidates.append(calibrate(structure, backbone, cyclic, p.laws, forms[1]))
        candidates.sort(key=lambda c: c.fits[c.law].worst)  # the pushovers' choice first
        calibration = candidates[0]
        amplitudes = sorted(p.cycle_amplitudes)[-3:]  # the probes' and refinement's drifts
        if p.law_choice == "dynamic" and sum(len(c.fits) for c in candidates) > 1:
            errors = dynamic_errors(structure, candidates, floors, amplitudes)
            if errors is not None:
                calibration = _dynamic_choice(candidates, errors)
        if p.refine_records:
            calibration = refine(structure, calibration, floors, amplitudes, p.refine_records)
        calibration = _integrated(calibration, p.integrator, amplitudes)
        warn_where_off(structure, calibration, p.tolerance)
        return self._built(calibration, floors)

    def restore(self, structure: Structure, directory: Path) -> Stick:
        """The stick of the calibration :meth:`write_artifacts` saved in ``directory``
        (``stick.json``), without pushing the structure again; :meth:`fit` where there is
        none."""
        saved = Path(directory) / "stick.json"
        if not saved.is_file():
            return self.fit(structure)
        self.check(structure)
        calibration = StickCalibration.from_dict(json.loads(saved.read_text()))
        floors = _floors(structure.stories(), structure.n_outputs, structure.name)
        return self._built(calibration, floors)

    def _built(self, calibration: StickCalibration, floors: np.ndarray) -> Stick:
        self.calibration_ = calibration
        self.stick_ = calibration.building()
        self.floors_ = floors
        return self

    def calibration(self) -> dict[str, Any]:
        """``{"stick": ..., "floors": ...}``: the parameters of the stick's
        ``shear-building`` (masses, story stiffnesses, heights, the story law's name and its
        parameters per story, damping, the coupling between the floors or None) and the
        stick floor of each output."""
        check_fitted(self, "stick_")
        return {"stick": self.stick_.get_params(), "floors": self.floors_.tolist()}

    def refit_params(self) -> dict[str, Any]:
        """These parameters with ``laws`` the law, coupling and integrator this stick
        chose: every member of a family gets the same."""
        check_fitted(self, "stick_")
        params = self.stick_.get_params()
        chosen = params["story_law"]["name"]
        coupling = "none" if params["coupling"] is None else "floors"
        return {
            **self.get_params(),
            "laws": [chosen],
            "law_choice": "pushover",
            "coupling": coupling,
            "integrator": params["integrator"],
        }

    def calibrated(self, structure: Structure, calibration: dict[str, Any]) -> Stick:
        """The stick of ``calibration`` (as :meth:`calibration` gives it) for
        ``structure``, a member of the family of the structure it was fitted to, without
        pushing it or reading its stories; the story law's parameters are held within the
        bounds the fit allows them (an interpolated calibration may overshoot one that
        sits at its bound). It has no ``calibration_`` (no pushover to show).

        Raises:
            CapabilityError: the structure lacks what :meth:`fit` needs.
            ConfigError: the calibration's floors are not one per output of the structure.
        """
        self.check(structure)
        if not {"stick", "floors"} <= set(calibration):
            raise ConfigError(
                "stick: a calibration holds 'stick' and 'floors', as Stick.calibration() gives "
                f"them; got {', '.join(sorted(calibration)) or 'nothing'}"
            )
        floors = np.asarray(calibration["floors"], dtype=int)
        if floors.shape != (structure.n_outputs,):
            raise ConfigError(
                f"stick: the calibration gives floors for {floors.size} outputs; structure "
                f"'{structure.name}' has {structure.n_outputs}"
            )
        stick = dict(calibration["stick"])
        law = stick["story_law"]
        if law["name"] in LAW_SPACES:
            stick["story_law"] = LAW_SPACES[law["name"]].held_within_fit(law)
        self.stick_ = create("structure", "shear-building", **stick)
        self.floors_ = floors
        return self

    def transform(self, motions: GroundMotions) -> np.ndarray:
        """``[n_records, n_steps, n_outputs]`` floor displacements (m) of the stick on the
        motion's grid; NaN from where a story of a softening stick lost its strength (a
        collapse of the stick, with a :class:`~cphysfno_core.CphysfnoWarning` naming the
        records: no physics input for them)."""
        check_fitted(self, "stick_")
        responses = self.stick_.simulate(motions)
        if responses.collapsed.any():
            records = np.flatnonzero(responses.collapsed)
            warnings.warn(
                f"stick: {records.size} of {motions.n_records} records (first "
                f"{records[:5].tolist()}) drive a story of the stick past the drift where its "
                "softening law has no strength left: the stick collapses and its z is NaN "
                "from there",
                CphysfnoWarning,
                stacklevel=2,
            )
        return responses.displacement[:, :, self.floors_]

    def write_artifacts(self, directory: Path) -> list[Path]:
        """The calibration (``stick.json``), its summary (``summary.md``, with a warning
        where the stick does not follow the structure) and ``stick.png`` (each story's
        curves, structure against stick): :func:`~.stick_figures.write_stick_artifacts`."""
        check_fitted(self, "calibration_")
        return write_stick_artifacts(self.calibration_, Path(directory))


def _dynamic_choice(
    candidates: list[StickCalibration], errors: list[dict[str, float]]
) -> StickCalibration:
    """The candidate and law of the lowest probe error (a tie, :func:`first_within_tie`,
    to the candidate and law listed first), with every candidate's errors (``"<law>"``
    with the coupling, ``"<law> (springs alone)"`` without, where both were fitted).

    Where springs alone follow the structure within :data:`~.stick_probes.FOLLOWS`, the
    closest such stick is kept even if a coupled one is closer still: closer than that the
    two differ by about what the integrators do, and springs alone are the cheaper stick
    (a tridiagonal stiffness, and higher periods longer than the frame's, so fewer
    central-difference steps a sample)."""
    both = len({c.coupling is None for c in candidates}) > 1
    labelled, by_pair = {}, {}
    for index, (calibration, found) in enumerate(zip(candidates, errors, strict=True)):
        suffix = SPRINGS_ALONE if both and calibration.coupling is None else ""
        for law, error in found.items():
            labelled[law + suffix] = error
            by_pair[index, law] = error
    cheap = {
        pair: error
        for pair, error in by_pair.items()
        if candidates[pair[0]].coupling is None and error <= FOLLOWS
    }
    index, law = first_within_tie(cheap or by_pair)
    return dataclasses.replace(candidates[index], law=law, dynamic_errors=labelled)


def _integrated(
    calibration: StickCalibration, integrator: str, amplitudes: list[float]
) -> StickCalibration:
    """The calibration on ``integrator``; for ``"choose"``, on central difference where
    :func:`~.stick_probes.integrator_error` is within :data:`INTEGRATOR_TOLERANCE`, else on
    Runge-Kutta, with that error."""
    if integrator != "choose":
        return dataclasses.replace(calibration, integrator=integrator)
    error = integrator_error(calibration, amplitudes)
    chosen = "central-difference" if error <= INTEGRATOR_TOLERANCE else "runge-kutta"
    return dataclasses.replace(calibration, integrator=chosen, integrator_error=error)


def _floors(stories: Stories, n_outputs: int, name: str) -> np.ndarray:
    """``[n_outputs]`` the stick floor (story top, from 0) of each output.

    Raises:
        ConfigError: the stories are not stacked (each from the top of the one below), or
            an output is no story's top.
    """
    tops = {output: floor for floor, output in enumerate(stories.upper)}
    if not stories.is_stacked or set(tops) != set(range(n_outputs)):
        raise ConfigError(
            f"stick: structure '{name}' needs stories one above the other whose tops are its "
            f"outputs (got bottoms {stories.lower}, tops {stories.upper} for {n_outputs} outputs)"
        )
    return np.array([tops[i] for i in range(n_outputs)])
