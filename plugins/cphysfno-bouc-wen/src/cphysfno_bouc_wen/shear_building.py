"""Any nonlinear shear building: a chain of story springs that follow a story law."""

from __future__ import annotations

import math
from functools import cached_property
from typing import Annotated, Any, Literal

import numpy as np
from cphysfno_core import ConfigError, CphysfnoError, GroundMotions, InputError, Responses
from cphysfno_core.plugin import (
    LinearSystem,
    Params,
    Rayleigh,
    Stories,
    StoryLaw,
    StoryPushover,
    Structure,
    get_registry,
    per_story,
    validate_params,
)
from cphysfno_core.signals import (
    check_time_step,
    coupling_story_shear,
    first_mode_pattern,
    lateral_pattern,
)
from pydantic import Field, field_validator, model_validator

from .central_difference import central_difference_kernel
from .chain import StoryChain, project_chain
from .explicit import integrate_rk4
from .generic import integrate_chain, rk4_kernel, story_test_kernel
from .implicit import StepFailure, integrate_gauss
from .law_force import StoryLawRestoringForce
from .laws import BoucWenLaw
from .model import ShearBuildingModel, classical_damping, elastic_modes, elastic_stiffness
from .reduced import ReducedModel, reduce
from .restoring import BoucWenRestoringForce

Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]
PerStory = Positive | tuple[Positive, ...]

STORY_TEST_RESOLUTION = 1e-3
"""Largest Runge-Kutta step of the story test (:meth:`ShearBuilding.story_shears`) as a
fraction of the story's largest drift: where a law turns a corner within a step, its force
there is off by at most about half a step. The steps depend on the drift history only, so
that the shears change continuously with the law's parameters."""

AUTOMATIC_RETRIES = (4, 4)
"""Where the automatic step diverges on a record, it is integrated again with this many
times more steps, twice (16 times in all), before the integration is said to diverge."""

MAX_STEP_ANGLE = {"runge-kutta": 0.45, "central-difference": 1.0}
"""Largest ``omega_max h`` (rad) of an automatically chosen step ``h`` of each integrator.
Runge-Kutta: the relative L2 error stays near 1e-4 (2e-4 to 3e-4 where the stories
yield). Central difference (stable below 2): the shortest period is about 4 % short, the
first ones far less (tests/test_central_difference.py measures the error)."""

SCHEMES = {"runge-kutta": rk4_kernel, "central-difference": central_difference_kernel}
"""The compiled integrator of each ``integrator``, for any story law."""


class ShearBuildingParams(Params):
    """Parameters of :class:`ShearBuilding`. Per-story values are a scalar or one value per
    story, bottom story first."""

    masses: PerStory = Field(description="floor masses, kg")
    stiffnesses: PerStory = Field(description="initial story stiffnesses, N/m")
    n_stories: int | None = Field(
        None, ge=1, le=200, description="number of stories when every per-story value is a scalar"
    )
    story_law: dict[str, Any] = Field(
        default_factory=lambda: {"name": "bouc-wen"},
        description='the hysteresis of every story spring: {name = "...", its parameters}',
    )
    damping_ratio: float = Field(0.05, ge=0.0, lt=1.0, description="viscous damping ratio")
    rayleigh_modes: tuple[int, int] | None = Field(
        None,
        description="two modes (1-based) at which mass- and initial-stiffness-proportional "
        "Rayleigh damping gives damping_ratio; None: classical damping, the ratio in every mode",
    )
    story_heights: PerStory = Field(3.0, description="story heights, m (for drift ratios)")
    coupling: tuple[tuple[float, ...], ...] | None = Field(
        None,
        description="[d, d] symmetric linear stiffness (N/m) between the floors, added to "
        "the story springs' forces: what a frame's flexure adds to its stories' shear "
        "springs (the stick's); None: none",
    )
    integrator: Literal["runge-kutta", "central-difference"] = Field(
        "runge-kutta",
        description="'runge-kutta': classical fourth order, four evaluations of the story "
        "laws a step; 'central-difference': explicit Newmark, second order, one evaluation "
        "a step (several times faster, less accurate in the highest modes)",
    )
    substeps: int | None = Field(
        None,
        ge=1,
        le=1000,
        description="integration steps per sample of the motion; None keeps "
        "omega_max h <= 0.45 rad (runge-kutta) or 1 rad (central-difference) and "
        "integrates a record that diverges again with 4, then 16 times more steps",
    )
    precision: Literal["float32", "float64"] = Field(
        "float64",
        description="arithmetic on the motion's grid (float32 only speeds up a uniform "
        "bouc-wen law)",
    )

    @field_validator("story_law")
    @classmethod
    def _law_has_name(cls, law: dict[str, Any]) -> dict[str, Any]:
        if not isinstance(law.get("name"), str):
            raise ValueError('needs a name, e.g. {name = "bilinear", yield_displacement = 0.01}')
        return law

    @field_validator("rayleigh_modes")
    @classmethod
    def _distinct_modes(cls, modes: tuple[int, int] | None) -> tuple[int, int] | None:
        if modes is not None and (min(modes) < 1 or modes[0] == modes[1]):
            raise ValueError(f"needs two distinct modes numbered from 1, got {list(modes)}")
        return modes

    @model_validator(mode="after")
    def _consistent_story_count(self) -> ShearBuildingParams:
        lengths = {
            field: len(value)
            for field in ("masses", "stiffnesses", "story_heights")
            if isinstance(value := getattr(self, field), tuple)
        }
        if self.n_stories is not None:
            lengths["n_stories"] = self.n_stories
        if not lengths:
            raise ValueError(
                "masses and stiffnesses are scalars: give n_stories, or one value per story"
            )
        if len(set(lengths.values())) > 1:
            found = ", ".join(f"{field} {n}" for field, n in lengths.items())
            raise ValueError(f"the number of stories differs between fields: {found}")
        if self.coupling is not None:
            d = next(iter(lengths.values()))
            rows = {len(row) for row in self.coupling}
            if len(self.coupling) != d or rows != {d}:
                raise ValueError(f"coupling must be a [{d}, {d}] matrix of N/m")
            coupling = np.array(self.coupling, dtype=np.float64)
            if not np.isfinite(coupling).all():
                raise ValueError("coupling must be finite")
            if not np.allclose(coupling, coupling.T, rtol=1e-9, atol=1e-9 * np.abs(coupling).max()):
                raise ValueError("coupling must be symmetric")
        return self


class ShearBuilding(Structure):
    """A nonlinear shear building: floors joined by story springs that follow a story law.

    ``M u'' + C u' + A_f^T F(v, s) = -M 1 a_g`` with floor displacements ``u`` relative to
    the ground, story drifts ``v = A_f u`` (``v_i = u_i - u_(i-1)``, ``u_0 = 0``) and the
    story shears ``F`` of the law (``story_law``, any registered law) with its state ``s``.
    A ``coupling`` matrix ``K_c`` adds the linear floor forces ``K_c u`` (a frame's flexure
    that story springs do not hold); the elastic stiffness is then ``A_f^T diag(k) A_f +
    K_c``. ``C`` is classical (the damping ratio in every elastic mode) or Rayleigh at two
    modes, on that elastic stiffness.
    The ground acceleration is linear between its samples; the building starts at rest.

    :meth:`simulate` integrates all records with classical Runge-Kutta in compiled code:
    the law's functions inlined into a kernel made for them, float64; a ``bouc-wen`` law
    with the same parameters in every story and no coupling takes the dedicated
    vectorised kernel of the paper's Example 1 building instead (the same equations,
    several times faster).

    Outputs are the floor displacements relative to the ground (m), bottom floor first,
    with the extras ``"story_drift"`` (m) and ``"story_shear"`` (N, the springs' and the
    coupling's), each ``[n, T, n_stories]``. A story law that softens past yield
    (``alpha < 0``) loses its strength at a large enough drift; a record that drives a
    story there runs away and is flagged ``collapsed`` (:attr:`Responses.collapsed`), its
    rows NaN from where the integration overflowed.
    """

    name = "shear-building"
    Params = ShearBuildingParams
    capabilities = frozenset(
        {
            "linear_system",
            "restoring_force",
            "coarse_simulation",
            "projected_simulation",
            "stories",
            "pushover",
        }
    )

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        self.law_coefficients  # noqa: B018 - the law's parameters fail here, not at first use

    @cached_property
    def n_stories(self) -> int:
        """Number of stories (= floors)."""
        p = self.params
        for value in (p.masses, p.stiffnesses, p.story_heights):
            if isinstance(value, tuple):
                return len(value)
        return int(p.n_stories)

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(f"story-{i + 1}" for i in range(self.n_stories))

    @cached_property
    def masses(self) -> np.ndarray:
        """``[d]`` floor masses, kg."""
        return per_story(self.params.masses, self.n_stories, "masses")

    @cached_property
    def story_stiffnesses(self) -> np.ndarray:
        """``[d]`` initial story stiffnesses, N/m."""
        return per_story(self.params.stiffnesses, self.n_stories, "stiffnesses")

    @cached_property
    def story_heights(self) -> np.ndarray:
        """``[d]`` story heights, m."""
        return per_story(self.params.story_heights, self.n_stories, "story_heights")

    @cached_property
    def story_law(self) -> StoryLaw:
        """The story law, built from ``story_law`` through the registry."""
        spec = dict(self.params.story_law)
        name = spec.pop("name")
        law_class = get_registry().get("story_law", name)
        validate_params(law_class.Params, spec, "story_law")
        return law_class(**spec)

    @property
    def rayleigh_modes(self) -> tuple[int, int] | None:
        """The two modes of Rayleigh damping, or ``None`` for classical damping."""
        return self.params.rayleigh_modes

    @property
    def integrator(self) -> str:
        """``"runge-kutta"`` or ``"central-difference"``: the scheme on the motion's grid."""
        return self.params.integrator

    @cached_property
    def law_coefficients(self) -> np.ndarray:
        """``[d, n_c]`` the law's coefficients of each story."""
        return self.story_law.coefficients(self.story_stiffnesses)

    @cached_property
    def coupling(self) -> np.ndarray:
        """``[d, d]`` the linear stiffness between the floors beside the story springs, N/m
        (zeros where there is none)."""
        if self.params.coupling is None:
            return np.zeros((self.n_stories, self.n_stories))
        return np.array(self.params.coupling, dtype=np.float64)

    @cached_property
    def _matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        mass = self.masses
        stiffness = elastic_stiffness(self.story_stiffnesses) + self.coupling
        if self.coupling.any() and np.linalg.eigvalsh(stiffness)[0] <= 0.0:
            raise ConfigError(
                f"{self.name}: the story stiffnesses with the coupling give a stiffness "
                "matrix that is not positive definite"
            )
        modes = self.rayleigh_modes
        if modes is None:
            return mass, stiffness, classical_damping(mass, stiffness, self.params.damping_ratio)
        omega, _ = elastic_modes(mass, stiffness)
        if max(modes) > len(omega):
            raise ConfigError(
                f"{self.name}: rayleigh_modes {list(modes)} asks for mode {max(modes)} of a "
                f"{len(omega)}-story building"
            )
        rayleigh = Rayleigh.matching(
            omega[modes[0] - 1], omega[modes[1] - 1], self.params.damping_ratio
        )
        return mass, stiffness, rayleigh.matrix(np.diag(mass), stiffness)

    @cached_property
    def _bouc_wen_model(self) -> ShearBuildingModel | None:
        """The model of the dedicated kernel, for a uniform ``bouc-wen`` law; else None."""
        law = self.story_law
        if (
            not (isinstance(law, BoucWenLaw) and law.uniform())
            or self.coupling.any()
            or self.integrator != "runge-kutta"
        ):
            return None
        k, alpha, a, beta, gamma, exponent = self.law_coefficients[0]
        mass, _, damping = self._matrices
        return ShearBuildingModel(
            mass, damping, self.story_stiffnesses, alpha, a, beta, gamma, exponent
        )

    def _chain(self, basis: np.ndarray) -> StoryChain:
        mass, stiffness, damping = self._matrices
        return project_chain(mass, damping, stiffness, self.coupling, self.law_coefficients, basis)

    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        """Nonlinear response of every record.

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            dt: ``None``: the response on the motion's grid. A step in s no shorter than
                the motion's own resamples the motion onto that grid (linear between
                samples) and returns the response there: with the dedicated Bouc-Wen kernel
                one three-stage Gauss-Legendre step per interval (float64, stable for any
                step); with any other law the same Runge-Kutta kernel as on the fine grid,
                with as many steps per interval as stability needs (the coarse response
                then differs from the fine one only by the coarser motion).

        Raises:
            InputError: ``motions`` is not a GroundMotions, or ``dt`` is not a positive
                time step at least the motion's.
            CphysfnoError: the integration failed on a record (named in the message).
        """
        self._check_motions(motions)
        if dt is None:
            return self._integrate(motions, np.eye(self.n_stories), self.params.substeps)
        dt = check_time_step(dt, "dt")
        if dt < motions.dt * (1.0 - 1e-9):
            raise InputError(
                f"{self.name}: a coarse dt must be at least the motion's dt = {motions.dt} s, "
                f"got {dt} s; use dt=None for the motion's own grid"
            )
        coarse = motions.resample(dt)
        if self._bouc_wen_model is None:
            return self._integrate(coarse, np.eye(self.n_stories), None)
        return self._simulate_gauss(coarse)

    def simulate_projected(
        self, motions: GroundMotions, basis: np.ndarray, *, substeps: int | None = None
    ) -> Responses:
        """Nonlinear response of the model Galerkin-projected onto ``basis``.

        With floor displacements ``u = basis q``, the equations of motion multiplied by
        ``basis^T`` are integrated on the motion's grid with classical Runge-Kutta, as
        :meth:`simulate` does with ``dt=None`` (which is the identity basis).

        Args:
            motions: ``[n, T]`` ground accelerations in m/s^2.
            basis: ``[n_stories, r]`` floor displacement shapes, linearly independent.
            substeps: Runge-Kutta steps per sample; ``None`` takes the parameter
                ``substeps``.

        Returns:
            Floor displacements ``[n, T, n_stories]`` (m) with the extras of
            :meth:`simulate`.

        Raises:
            InputError: ``motions`` is not a GroundMotions, or ``basis`` is not a
                ``[n_stories, r]`` array of full column rank, or ``substeps < 1``.
            CphysfnoError: the integration diverged on a record (named in the message).
        """
        self._check_motions(motions)
        d = self.n_stories
        basis = np.asarray(basis, dtype=np.float64)
        if basis.ndim != 2 or basis.shape[0] != d or np.linalg.matrix_rank(basis) < basis.shape[1]:
            raise InputError(
                f"{self.name}: basis must be [{d}, r] with linearly independent columns, "
                f"got shape {basis.shape}"
            )
        if substeps is None:
            substeps = self.params.substeps
        if substeps is not None and (
            isinstance(substeps, bool) or not isinstance(substeps, int | np.integer) or substeps < 1
        ):
            raise InputError(f"{self.name}: substeps must be an integer >= 1, got {substeps!r}")
        return self._integrate(motions, basis, substeps)

    def _integrate(
        self, motions: GroundMotions, basis: np.ndarray, substeps: int | None
    ) -> Responses:
        automatic = substeps is None
        if automatic:
            omega_max = 2.0 * np.pi / self.periods()[-1]
            angle = MAX_STEP_ANGLE[self.integrator]
            substeps = max(1, math.ceil(omega_max * motions.dt / angle))
        displacement, drift, shear, finite = self._kernel(motions, basis, substeps)
        for factor in AUTOMATIC_RETRIES if automatic and not self.softens else ():
            if finite.all():
                break
            # a stiff hysteresis (a sharp Bouc-Wen corner) can outrun the periods' step
            rows = np.flatnonzero(~finite)
            substeps *= factor
            again = self._kernel(motions[rows], basis, substeps)
            for values, redone in zip((displacement, drift, shear, finite), again, strict=True):
                values[rows] = redone
        if self.coupling.any():
            shear = shear + coupling_story_shear(self.coupling, drift)
        extras = {"story_drift": drift, "story_shear": shear}
        if not finite.all() and not self.softens:
            raise CphysfnoError(
                f"{self.name}: the {self.integrator} integration diverged for record "
                f"{int(np.argmin(finite))}: its step dt/substeps = "
                f"{motions.dt / substeps:.3g} s is too long for the shortest period "
                f"{self.periods()[-1]:.3g} s; raise substeps"
            )
        if not self.softens:
            return Responses(displacement, motions.dt, extras)
        # a story past the drift where its strength is gone runs away: a collapse, NaN after
        past = np.abs(drift) > self.strength_lost_drift
        gone = ~np.isfinite(drift).all(axis=2) | past.any(axis=2)
        after = np.logical_or.accumulate(gone, axis=1)
        for values in (displacement, *extras.values()):
            values[after] = np.nan
        return Responses(displacement, motions.dt, extras, collapsed=after[:, -1])

    def _kernel(
        self, motions: GroundMotions, basis: np.ndarray, substeps: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(displacement, story drift, story shear, [n] finite)`` of the compiled
        Runge-Kutta integration with ``substeps`` steps per sample."""
        model = self._bouc_wen_model
        if model is not None:
            precision = np.float32 if self.params.precision == "float32" else np.float64
            reduced: ReducedModel = reduce(model, basis)
            return integrate_rk4(reduced, motions.acceleration, motions.dt, substeps, precision)
        law = self.story_law
        return integrate_chain(
            self._chain(basis),
            law.functions(),
            law.n_states,
            motions.acceleration,
            motions.dt,
            substeps,
            scheme=SCHEMES[self.integrator],
        )

    @cached_property
    def strength_lost_drift(self) -> np.ndarray:
        """``[d]`` the drift (m) past which each story has no strength left (its law's
        :meth:`~cphysfno_core.plugin.StoryLaw.strength_lost_drift`; inf where it keeps
        some). With a coupling this is the spring's alone: a record past it counts as a
        collapse although the coupling's elastic share of the story's strength remains
        (its spring fitted to the pushover less that share has none left)."""
        return self.story_law.strength_lost_drift(self.n_stories)

    @property
    def softens(self) -> bool:
        """Whether a story's strength may be lost (a story law that softens past yield,
        ``alpha < 0``): a record that drives it past :attr:`strength_lost_drift`
        collapses."""
        return bool(np.isfinite(self.strength_lost_drift).any())

    def _simulate_gauss(self, motions: GroundMotions) -> Responses:
        model = self._bouc_wen_model
        try:
            displacement, drift, shear = integrate_gauss(
                reduce(model, np.eye(self.n_stories)),
                motions.acceleration,
                motions.dt,
                (model.a / (model.delta + model.zeta)) ** (1.0 / model.exponent),
            )
        except StepFailure as failure:
            detail = f" {motions.metadata[failure.record]}" if motions.metadata else ""
            raise CphysfnoError(f"{self.name}: {failure}{detail}") from None
        return Responses(displacement, motions.dt, {"story_drift": drift, "story_shear": shear})

    def _check_motions(self, motions: GroundMotions) -> None:
        if not isinstance(motions, GroundMotions):
            raise InputError(
                f"{self.name}: motions must be a cphysfno_core.GroundMotions, "
                f"got {type(motions).__name__}"
            )

    def periods(self, n: int | None = None) -> np.ndarray:
        """First ``n`` (default all) elastic natural periods in s, longest first."""
        d = self.n_stories
        if n is None:
            n = d
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= d:
            raise ConfigError(f"{self.name}: n must be an integer from 1 to {d}, got {n!r}")
        mass, stiffness, _ = self._matrices
        omega, _ = elastic_modes(mass, stiffness)
        return 2.0 * np.pi / omega[: int(n)]

    def stories(self) -> Stories:
        """The stories one above the other, the outputs being the floors bottom-up, each
        ``story_heights`` high (m)."""
        return Stories.stacked(tuple(float(h) for h in self.story_heights))

    def story_shears(self, drift: np.ndarray) -> np.ndarray:
        """The story test: each story's shear along a drift history imposed on it alone.

        Each story starts from rest and its law is driven along its column of ``drift``,
        linear between the samples, the law's rate integrated over each increment with
        classical Runge-Kutta steps of at most :data:`STORY_TEST_RESOLUTION` times the
        story's largest drift and ``settle`` after each
        (the stories of a shear building are independent springs, so this is also their
        part in any static analysis; a ``coupling`` carries shear of its own beside them,
        which :meth:`story_pushover` adds).

        Args:
            drift: ``[p, n_stories]`` story drifts, m, starting anywhere (0 at rest).

        Returns:
            ``[p, n_stories]`` story shears, N.

        Raises:
            InputError: ``drift`` is not a finite ``[p, n_stories]`` array.
        """
        drift = np.asarray(drift, dtype=np.float64)
        if drift.ndim != 2 or drift.shape[1] != self.n_stories or not np.isfinite(drift).all():
            raise InputError(
                f"{self.name}: drift must be a finite [p, {self.n_stories}] array of m, got "
                f"shape {drift.shape}"
            )
        law = self.story_law
        largest_step = STORY_TEST_RESOLUTION * np.abs(drift).max(axis=0, initial=0.0)
        drive = story_test_kernel(law.functions(), law.n_states)
        return drive(
            np.ascontiguousarray(self.law_coefficients), np.ascontiguousarray(drift), largest_step
        )

    def story_pushover(
        self, roof_drift_ratio: np.ndarray, pattern: np.ndarray | None = None
    ) -> StoryPushover:
        """Each story's shear-drift curve as the roof follows ``roof_drift_ratio``.

        Without a coupling the stories of a shear building are independent springs, each
        loaded by its own shear only: under any lateral pattern a story's shear-drift
        relation is its law's, and the pattern changes only how far each story goes for a
        roof drift (a coupling's share depends on the whole displaced shape). This
        pushover deforms the building with the same drift ratio in every story (story
        ``i``'s drift is ``roof_drift_ratio`` times its height) and returns the story
        shears of :meth:`story_shears` along it (with the shears the ``coupling``
        carries, :func:`~cphysfno_core.signals.coupling_story_shear`); it never stops
        early (a story whose law softens past yield, a negative ``alpha``, loses strength
        along it).

        Args:
            roof_drift_ratio: ``[p]`` roof displacement over the building's height, from 0.
            pattern: ``[n_stories]`` lateral load shape, recorded with the curves;
                ``None``: first mode times mass.

        Raises:
            InputError: ``roof_drift_ratio`` is not a finite ``[p]`` array, or ``pattern``
                not ``n_stories`` values >= 0 of positive sum.
        """
        ratio = np.asarray(roof_drift_ratio, dtype=np.float64)
        if ratio.ndim != 1:
            raise InputError(f"{self.name}: roof_drift_ratio must be [p], got {ratio.shape}")
        drift = ratio[:, None] * self.story_heights[None, :]
        shear = self.story_shears(drift) + coupling_story_shear(self.coupling, drift)
        if pattern is None:
            pattern = first_mode_pattern(self.linear_system(), range(self.n_stories), self.masses)
        pattern = lateral_pattern(pattern, self.n_stories)
        return StoryPushover(ratio, drift, shear, self.masses, self.story_heights, pattern)

    def linear_system(self) -> LinearSystem:
        """Masses (kg), damping (N s/m), initial stiffness (N/m), influence ones, identity
        output map."""
        mass, stiffness, damping = self._matrices
        d = mass.shape[0]
        return LinearSystem(np.diag(mass), damping, stiffness, np.ones(d), np.eye(d))

    def restoring_force(self) -> BoucWenRestoringForce | StoryLawRestoringForce:
        """The story forces seen from the floors, ``A_f^T F(A_f u, s) + K_c u``, and the
        law's rate."""
        if self._bouc_wen_model is not None:
            return BoucWenRestoringForce(self._bouc_wen_model)
        return StoryLawRestoringForce(self.story_law, self.law_coefficients, self.coupling)
