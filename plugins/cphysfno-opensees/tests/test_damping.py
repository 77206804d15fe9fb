"""The damping choices of ``opensees-model`` (Rayleigh on the initial or the committed
stiffness, over a region only, and modal damping) against OpenSeesPy run directly on the
same script with the same damping command, and the damping matrix of the linear system
against what each command damps."""

from __future__ import annotations

import numpy as np
import pytest
import script_models as sm

import cphysfno_core as cp
from cphysfno_core import GroundMotions
from cphysfno_core.testing.physics import linear_response

FLOORS = [[11, 1], [21, 1]]
SPRING_FLOORS = [[1, 1], [2, 1], [3, 1]]


@pytest.fixture(scope="module")
def springs_script(folder):
    """Three stories of Steel01 springs on the ground's elevation, the springs taking the
    stiffness part of Rayleigh damping (``-doRayleigh 1``)."""
    stiffness = (4.0e7, 3.0e7, 2.0e7)
    return sm.springs(
        folder, stiffness=stiffness, yield_force=tuple(0.01 * k for k in stiffness),
        masses=(2.0e4,) * 3, rayleigh=True,
    )  # fmt: skip


@pytest.fixture(scope="module")
def strong():
    return sm.records(n=2, peak=4.0)


def _frame(script, **damping):
    return cp.create(
        "structure", "opensees-model", script=str(script), outputs=FLOORS, gravity="gravity",
        **damping,
    )  # fmt: skip


def _against_direct(model, script, outputs, motions, damping, *, gravity: bool):
    u = model.simulate(motions).displacement
    for i, record in enumerate(motions.acceleration):
        direct = sm.direct_run(script, outputs, record, motions.dt, gravity=gravity,
                               damping=damping)  # fmt: skip
        assert np.all(sm.relative_l2(u[i], direct.displacement) < 1e-6)
    return u


def test_rayleigh_on_the_committed_stiffness_is_openseess_betakcomm(frame_script, strong):
    model = _frame(frame_script, damping="rayleigh-committed")
    committed = _against_direct(
        model, frame_script, [(11, 1), (21, 1)], strong,
        lambda ops, a, b: ops.rayleigh(a, 0.0, 0.0, b), gravity=True,
    )  # fmt: skip
    initial = _frame(frame_script).simulate(strong).displacement
    assert np.all(sm.relative_l2(committed, initial) > 1e-4)  # the columns yield: it differs
    # at the gravity state the committed stiffness is the tangent: a0 M + a1 K there
    system, factors = model.linear_system(), model.summary.damping_setup.rayleigh
    expected = factors.matrix(system.mass, system.stiffness)
    np.testing.assert_allclose(system.damping, expected, rtol=1e-6, atol=1e-9 * expected.max())


def test_modal_damping_is_openseess_modal_damping(frame_script, strong):
    model = _frame(frame_script, damping="modal", damping_ratio=0.03)

    def modal(ops, a, b):
        ops.eigen("-fullGenLapack", 2)
        ops.modalDamping(0.03)

    _against_direct(model, frame_script, [(11, 1), (21, 1)], strong, modal, gravity=True)
    system = model.linear_system()
    squares, shapes = np.linalg.eig(np.linalg.solve(system.mass, system.stiffness))
    shapes = shapes / np.sqrt(np.einsum("ij,jk,ki->i", shapes.T, system.mass, shapes))
    modal_damping = shapes.T @ system.damping @ shapes
    np.testing.assert_allclose(
        np.diag(modal_damping), 2 * 0.03 * np.sqrt(squares), rtol=1e-9
    )  # 3 % in each mode
    assert np.abs(modal_damping - np.diag(np.diag(modal_damping))).max() < 1e-9 * np.sqrt(
        squares
    ).max()


def test_modal_ratios_per_mode_and_the_linear_system_follows_the_simulation(frame_script, strong):
    model = _frame(frame_script, damping="modal", modal_ratios=[0.02, 0.08])

    def modal(ops, a, b):
        ops.eigen("-fullGenLapack", 2)
        ops.modalDamping(0.02, 0.08)

    _against_direct(model, frame_script, [(11, 1), (21, 1)], strong, modal, gravity=True)
    small = GroundMotions(0.01 * strong.acceleration, strong.dt)
    fine = model.simulate(sm.finer(small, 16)).displacement[:, ::16]
    # the linear system (ELS) carries the same damping: it is the elastic response
    assert np.all(sm.relative_l2(linear_response(model.linear_system(), small), fine) < 5e-3)


def test_a_damping_region_leaves_the_first_story_undamped(springs_script, strong):
    region = {"nodes": [2, 3], "elements": [2, 3]}  # the first spring and floor undamped
    model = cp.create(
        "structure", "opensees-model", script=str(springs_script), outputs=SPRING_FLOORS,
        damping_region=region,
    )  # fmt: skip

    def regional(ops, a, b):
        ops.region(1, "-eleOnly", 2, 3, "-rayleigh", a, 0.0, b, 0.0)
        ops.region(2, "-nodeOnly", 2, 3, "-rayleigh", a, 0.0, 0.0, 0.0)

    u = _against_direct(model, springs_script, [(1, 1), (2, 1), (3, 1)], strong, regional,
                        gravity=False)  # fmt: skip
    whole = cp.create(
        "structure", "opensees-model", script=str(springs_script), outputs=SPRING_FLOORS
    )
    assert np.all(sm.relative_l2(u, whole.simulate(strong).displacement) > 1e-3)
    damping, factors = model.linear_system().damping, model.summary.damping_setup.rayleigh
    k1 = 4.0e7
    # no dashpot on the first spring or at the first floor: its row is the second spring's
    # -b k2 and its diagonal b k2 only
    np.testing.assert_allclose(damping[0, 0], factors.stiffness_factor * 3.0e7, rtol=1e-9)
    assert damping[0, 0] < factors.stiffness_factor * (k1 + 3.0e7)
    np.testing.assert_allclose(
        damping[1, 1], factors.mass_factor * 2.0e4 + factors.stiffness_factor * 5.0e7, rtol=1e-9
    )


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"modal_ratios": [0.02]}, "modal_ratios: only with damping = 'modal'"),
        ({"damping": "modal", "damping_region": {"nodes": [11]}}, "damping_region: only with"),
        ({"damping_region": {}}, "give the nodes or the elements damped"),
        ({"damping": "modal", "modal_ratios": [0.02, 0.02, 0.02]}, "has 2 mode"),
        ({"damping": "viscous"}, "damping"),
    ],
)
def test_damping_settings_are_checked(frame_script, settings, message):
    with pytest.raises(cp.ConfigError, match=message):
        _frame(frame_script, **settings).periods()
