"""Small OpenSeesPy scripts for the ``opensees-model`` tests, and a direct OpenSeesPy
analysis of a script that does not go through the structure.

Each script is written in SI units scaled by two constants, ``LENGTH`` (model length
units per metre) and ``FORCE`` (model force units per newton), so that one text gives the
model in metres and newtons and the same model in inches and kips.
"""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np
import scipy.linalg

from cphysfno_core.testing.physics import smooth_random_motions

EXAMPLES = Path(__file__).parents[3] / "examples"
TINY = {
    "n_train": 4,
    "n_val": 2,
    "n_test": 2,
    "chunk_size": 8,
    "epochs": 1,
    "batch_size": 4,
    "layers": 1,
    "modes": 4,
    "width": 4,
    "projection_width": 8,
    "duration": 4.0,
    "copies": 1,
}
"""The sizes an example config is cut down to for an end-to-end test."""

METRES_PER_INCH = 0.0254
NEWTONS_PER_KIP = 4448.2216152605

UNITS = """
import openseespy.opensees as ops

LENGTH = {length!r}  # model length units per metre
FORCE = {force!r}  # model force units per newton
MASS = FORCE / LENGTH  # model mass units per kg
PASCAL = FORCE / LENGTH**2
"""

FRAME = (
    UNITS
    + '''
H, W = 3.0 * LENGTH, 5.0 * LENGTH
E = 2.0e11 * PASCAL
AREA, COLUMN_I, BEAM_I = 0.01 * LENGTH**2, 1.0e-4 * LENGTH**4, 2.0e-4 * LENGTH**4
YIELD_MOMENT = 6.0e4 * FORCE * LENGTH
JOINT_MASS = 1.0e4 * MASS
LEANING = {leaning!r}  # None, "chain" or "direct"


def build():
    """Two stories, one bay: P-Delta columns whose bending yields (bilinear moment-curvature
    sections of force-based elements), elastic beams, the joints of a floor tied
    horizontally, the floor mass lumped at its two joints; a pinned leaning column tied to
    the floors."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for floor in range(3):
        ops.node(10 * floor + 1, 0.0, floor * H)
        ops.node(10 * floor + 2, W, floor * H)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 1, 1, 1)
    ops.geomTransf("PDelta", 1)
    ops.geomTransf("Linear", 2)
    ops.uniaxialMaterial("Elastic", 1, E * AREA)
    ops.uniaxialMaterial("Steel01", 2, YIELD_MOMENT, E * COLUMN_I, 0.02)
    ops.section("Aggregator", 1, 1, "P", 2, "Mz")
    ops.beamIntegration("Lobatto", 1, 1, 3)
    for floor in (1, 2):
        for line in (1, 2):
            bottom, top = 10 * (floor - 1) + line, 10 * floor + line
            ops.element("forceBeamColumn", 100 + top, bottom, top, 1, 1)
        ops.element("elasticBeamColumn", 200 + floor, 10 * floor + 1, 10 * floor + 2,
                    AREA, E, BEAM_I, 2)
        ops.mass(10 * floor + 1, JOINT_MASS, 0.0, 0.0)
        ops.mass(10 * floor + 2, JOINT_MASS, 0.0, 0.0)
        ops.equalDOF(10 * floor + 1, 10 * floor + 2, 1)
    if LEANING is not None:
        ops.node(3, 2.0 * W, 0.0)
        ops.fix(3, 1, 1, 1)  # a truss leaves its rotations free: fix them
        ops.uniaxialMaterial("Elastic", 3, 100.0 * E * AREA)
        for floor in (1, 2):
            lean = 10 * floor + 3
            ops.node(lean, 2.0 * W, floor * H)
            ops.fix(lean, 0, 0, 1)
            below = 3 if floor == 1 else lean - 10
            ops.element("corotTruss", 300 + floor, below, lean, 1.0, 3)
            # "chain": tied to the joint that is itself tied to the floor's first joint
            ops.equalDOF(10 * floor + (2 if LEANING == "chain" else 1), lean, 1)


def gravity():
    """The frame's own weight at its joints and the floors' gravity load on the leaning
    column; not analysed here."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for floor in (1, 2):
        for line in (1, 2):
            ops.load(10 * floor + line, 0.0, -2.0e5 * FORCE, 0.0)
        if LEANING is not None:
            ops.load(10 * floor + 3, 0.0, -1.5e6 * FORCE, 0.0)
'''
)

HINGED = (
    UNITS
    + '''
H, W = 3.0 * LENGTH, 6.0 * LENGTH
E = 2.0e11 * PASCAL
AREA, COLUMN_I, BEAM_I = 0.01 * LENGTH**2, 1.5e-4 * LENGTH**4, 3.0e-4 * LENGTH**4
JOINT_MASS = 1.5e4 * MASS
HINGE_STIFFNESS = 20.0 * E * BEAM_I / W
HINGE_YIELD = 8.0e4 * FORCE * LENGTH


def build():
    """Two stories, one bay: elastic P-Delta columns; each beam an elastic element between
    two hinge nodes, joined to the joints by yielding rotational springs (zeroLength) and
    sharing their translations; masses on the joints' horizontal DOFs only, so that every
    rotation, every vertical DOF and every hinge node carries none."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for floor in range(3):
        ops.node(10 * floor + 1, 0.0, floor * H)
        ops.node(10 * floor + 2, W, floor * H)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 1, 1, 1)
    ops.geomTransf("PDelta", 1)
    ops.geomTransf("Linear", 2)
    ops.uniaxialMaterial("Steel01", 1, HINGE_YIELD, HINGE_STIFFNESS, 0.01)
    for floor in (1, 2):
        for line in (1, 2):
            bottom, top = 10 * (floor - 1) + line, 10 * floor + line
            ops.element("elasticBeamColumn", 100 + top, bottom, top, AREA, E, COLUMN_I, 1)
            hinge = 10 * floor + line + 4
            ops.node(hinge, *ops.nodeCoord(top))
            ops.equalDOF(top, hinge, 1, 2)
            ops.element("zeroLength", 400 + hinge, top, hinge, "-mat", 1, "-dir", 6)
            ops.mass(top, JOINT_MASS, 0.0, 0.0)
        ops.element("elasticBeamColumn", 200 + floor, 10 * floor + 5, 10 * floor + 6,
                    AREA, E, BEAM_I, 2)
'''
)


def write(
    folder: Path, name: str, text: str, *, length: float = 1.0, force: float = 1.0, **options
) -> Path:
    """The script ``text`` in the given units, written to ``folder/name.py``."""
    path = Path(folder) / f"{name}.py"
    path.write_text(text.format(length=length, force=force, **options))
    return path


def frame(folder: Path, name: str = "frame", leaning=None, **units) -> Path:
    return write(folder, name, FRAME, leaning=leaning, **units)


def hinged(folder: Path, name: str = "hinged", **units) -> Path:
    return write(folder, name, HINGED, **units)


SPRINGS = """
import openseespy.opensees as ops

STIFFNESS = {stiffness!r}  # N/m a story
YIELD_FORCE = {yield_force!r}  # N a story
MASSES = {masses!r}  # kg a floor


def build():
    \"\"\"A shear building of zeroLength Steel01 springs, every node at the ground's
    elevation: node 0 the ground, node s the floor over story s.\"\"\"
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for node in range(len(STIFFNESS) + 1):
        ops.node(node, 0.0, 0.0)
        ops.fix(node, 1 if node == 0 else 0, 1, 1)
    for story, (k, fy, m) in enumerate(zip(STIFFNESS, YIELD_FORCE, MASSES), start=1):
        ops.mass(story, m, 0.0, 0.0)
        ops.uniaxialMaterial("Steel01", story, fy, k, {hardening!r})
        ops.element("zeroLength", story, story - 1, story, "-mat", story, "-dir", 1,
                    "-doRayleigh", {rayleigh})
"""


def springs(
    folder: Path,
    name: str = "springs",
    *,
    stiffness: tuple[float, ...],
    yield_force: tuple[float, ...],
    masses: tuple[float, ...],
    hardening: float = 0.05,
    rayleigh: bool = False,
) -> Path:
    """A zeroLength shear building's script (:data:`SPRINGS`), its floors nodes 1 .. n; its
    springs take the stiffness part of the Rayleigh damping when ``rayleigh``."""
    return write(
        folder, name, SPRINGS,
        stiffness=tuple(float(k) for k in stiffness),
        yield_force=tuple(float(f) for f in yield_force),
        masses=tuple(float(m) for m in masses),
        hardening=float(hardening), rayleigh=int(rayleigh),
    )  # fmt: skip


def finer(motions, k: int):
    """The same motions on a grid ``k`` times finer, linear between their samples."""
    import cphysfno_core as cp

    time = np.arange((motions.n_steps - 1) * k + 1) * motions.dt / k
    values = np.stack([np.interp(time, motions.time, row) for row in motions.acceleration])
    return cp.GroundMotions(values, motions.dt / k)


def tiny_run(structure: dict):
    """The config of a run of ``structure`` at the smallest size: 8 white-noise records of
    3 s, ELS, a one-layer FNO trained one epoch, serial, no figures."""
    import cphysfno_core as cp

    return cp.parse_config(
        {
            "structure": structure,
            "ground_motion": {"name": "white-noise", "duration": 3.0},
            "preprocessor": [{"name": "els"}],
            "operator": {"name": "fno", "layers": 1, "modes": 4, "width": 4},
            "data": {"n_train": 4, "n_val": 2, "n_test": 2, "chunk_size": 8, "executor": "serial"},
            "training": {"epochs": 1, "batch_size": 2},
            "output": {"figures": False},
        }
    )


def records(n: int = 2, n_steps: int = 401, dt: float = 0.01, peak: float = 3.0, seed: int = 1):
    """Smooth random ground accelerations (m/s^2)."""
    return smooth_random_motions(n, n_steps, dt, peak, seed, window=5)


def load(path: Path):
    """The script at ``path`` as a module of its own."""
    spec = importlib.util.spec_from_file_location(f"direct_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


class DirectRun(NamedTuple):
    """What :func:`direct_run` found.

    Attributes:
        displacement: ``[T, n_outputs]`` from the gravity state, m.
        periods: ``[n]`` from OpenSees' eigen analysis at the gravity state, s.
        absolute_acceleration: ``[T, n_outputs]`` OpenSees' relative ``nodeAccel`` plus the
            ground acceleration for the outputs along DOF 1, m/s^2.
    """

    displacement: np.ndarray
    periods: np.ndarray
    absolute_acceleration: np.ndarray


def direct_run(
    path: Path,
    outputs: list[tuple[int, int]],
    acceleration: np.ndarray,
    dt: float,
    *,
    gravity: bool = False,
    damping_ratio: float = 0.05,
    modes: tuple[int, int] = (1, 2),
    metres_per_unit: float = 1.0,
    tolerance: float = 1e-8,
    held_gravity: str | None = None,
    convergence=None,
    damping=None,
) -> DirectRun:
    """The script analysed with OpenSeesPy alone, as one would by hand: gravity in ten
    load steps held constant (or the script's own ``held_gravity`` function, which
    analyses its loads and holds them), Rayleigh damping (mass and initial stiffness) matched to the
    eigen analysis of the gravity state in ``modes``, the record as a UniformExcitation in
    DOF 1, Newmark's average acceleration rule, Newton, the Transformation handler. Every
    step must converge, unless a convergence ladder (``ConvergenceParams``) is given:
    the steps are then taken by ``transient.integrate`` with it. ``damping(ops, a, b)``,
    given the Rayleigh factors ``a`` (1/s) and ``b`` (s), sets the damping instead of
    ``rayleigh a 0 b 0``.

    Returns:
        :class:`DirectRun`.
    """
    from cphysfno_opensees.loader import import_opensees
    from cphysfno_opensees.transient import integrate

    ops = import_opensees()
    script = load(path)
    ops.wipe()
    script.build()
    if gravity:
        script.gravity()
        analyse_gravity(ops, ("Transformation",), tolerance / metres_per_unit)
    if held_gravity is not None:  # a function that analyses its loads and holds them
        getattr(script, held_gravity)()
        ops.wipeAnalysis()
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    squares = np.asarray(ops.eigen("-fullGenLapack", max(modes)))
    ops.wipeAnalysis()
    omega = np.sqrt(squares)
    a, b = omega[modes[0] - 1], omega[modes[1] - 1]
    mass_factor = 2.0 * damping_ratio * a * b / (a + b)
    stiffness_factor = 2.0 * damping_ratio / (a + b)
    rest = np.array([ops.nodeDisp(node, dof) for node, dof in outputs])
    if damping is None:
        ops.rayleigh(mass_factor, 0.0, stiffness_factor, 0.0)
    else:
        damping(ops, mass_factor, stiffness_factor)
    values = np.asarray(acceleration, dtype=float) / metres_per_unit
    ops.timeSeries("Path", 77, "-dt", dt, "-values", *values)
    ops.pattern("UniformExcitation", 77, 1, "-accel", 77)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    test = ("NormDispIncr", tolerance / metres_per_unit, 25)
    ops.test(*test)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")

    def read() -> list[float]:
        return [ops.nodeDisp(node, dof) for node, dof in outputs] + [
            ops.nodeAccel(node, dof) for node, dof in outputs
        ]

    if convergence is None:
        rows = [read()]
        for _ in range(values.size - 1):
            assert ops.analyze(1, dt) == 0
            rows.append(read())
    else:
        rows = integrate(ops, values.size - 1, dt, read, test=test, convergence=convergence)
    ops.wipe()
    u, accelerations = np.hsplit(np.asarray(rows), 2)
    along = np.array([dof == 1 for _, dof in outputs], dtype=float)
    absolute = accelerations * metres_per_unit + np.outer(acceleration, along)
    return DirectRun((u - rest) * metres_per_unit, 2.0 * np.pi / omega, absolute)


def eigen_periods(path: Path, n: int, *, gravity: bool = False) -> np.ndarray:
    """``[n]`` periods (s) from OpenSees' eigen analysis of the script's model at rest
    under its gravity loads (Transformation handler)."""
    from cphysfno_opensees.loader import import_opensees

    ops = import_opensees()
    script = load(path)
    ops.wipe()
    script.build()
    if gravity:
        script.gravity()
        analyse_gravity(ops, ("Transformation",), 1e-8)
    ops.wipeAnalysis()
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    squares = np.asarray(ops.eigen("-fullGenLapack", n))
    ops.wipe()
    return 2.0 * np.pi / np.sqrt(squares)


def relative_l2(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per output (last axis) over everything else."""
    axes = tuple(range(truth.ndim - 1))
    return np.sqrt(((estimate - truth) ** 2).sum(axes) / (truth**2).sum(axes))


def eigh_periods(stiffness: np.ndarray, mass: np.ndarray) -> np.ndarray:
    return 2.0 * np.pi / np.sqrt(scipy.linalg.eigh(stiffness, mass, eigvals_only=True))


def tiny_example(name: str, folder: Path, **changes) -> Path:
    """``examples/<name>.toml`` at :data:`TINY` sizes with any other ``changes`` to its
    lines ``key = value``, written into ``folder`` with its script's path made absolute
    (the copy lies in another folder)."""
    text = (EXAMPLES / f"{name}.toml").read_text()
    for key, value in {**TINY, **changes}.items():
        text, count = re.subn(rf"(?m)^{key} = [^#\n]*", f"{key} = {value} ", text)
        assert count == 1, key
    text, count = re.subn(r'(?m)^script = "', f'script = "{EXAMPLES}/', text)
    assert count == 1
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def analyse_gravity(ops, handler: tuple, tolerance: float) -> None:
    """Analyse the gravity loads a script applied (ten load steps, Newton, ``handler``,
    ``tolerance`` on the displacement increment in model units) and hold them."""
    ops.constraints(*handler)
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", tolerance, 25)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.1)
    ops.analysis("Static")
    assert ops.analyze(10) == 0
    ops.loadConst("-time", 0.0)
    ops.wipeAnalysis()
